"""Fitting the reference-guided feedback's Gaussian mixtures (generator/feedback.py): per skeleton
and style, diagonal-covariance EM on the library's training frames (k-means++ start, fixed seed)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from g1_control.generator.feedback import Mixture, feedback_columns, save_mixtures

COMPONENTS = 12
MAX_FRAMES = 10000
VARIANCE_FLOOR = 1e-4
"""rad^2 / m^2: a joint the style holds still keeps a 1 cm / 0.01 rad spread."""


def fit_gmm(z: np.ndarray, k: int = COMPONENTS, iterations: int = 40, seed: int = 0) -> tuple:
    """z (N, d) -> (weights (k,), means (k, d), variances (k, d))."""
    rng = np.random.default_rng(seed)
    n = len(z)
    k = max(1, min(k, n // 20))
    scale = z.std(axis=0) + 1e-6
    zs = z / scale
    centres = [zs[rng.integers(n)]]
    for _ in range(1, k):
        d2 = np.min([((zs - c) ** 2).sum(1) for c in centres], axis=0)
        centres.append(zs[rng.choice(n, p=d2 / d2.sum())])
    means = np.array(centres) * scale
    variances = np.tile(z.var(axis=0) + VARIANCE_FLOOR, (k, 1))
    weights = np.full(k, 1.0 / k)
    for _ in range(iterations):
        m = Mixture(weights, means, variances, np.arange(z.shape[1]))
        r, _ = m.responsibilities(z)
        nk = r.sum(axis=0) + 1e-9
        weights = nk / n
        means = (r.T @ z) / nk[:, None]
        variances = (r.T @ (z * z)) / nk[:, None] - means ** 2 + VARIANCE_FLOOR
        variances = np.maximum(variances, VARIANCE_FLOOR)
    return weights, means, variances


def fit_mixtures(library_roots: dict[str, str | Path], seed: int = 0) -> dict[str, dict[str, Mixture]]:
    from g1_control.generator.data import load_split
    from g1_control.generator.styles import STYLES

    out: dict[str, dict[str, Mixture]] = {}
    for sk, root in library_roots.items():
        feats, styles = load_split(root, "train", sk)
        cols = feedback_columns(sk)
        by_style: dict[str, Mixture] = {}
        for sid in sorted(set(styles)):
            z = np.concatenate([f[:, cols] for f, s in zip(feats, styles) if s == sid])
            if len(z) > MAX_FRAMES:
                z = z[np.random.default_rng(seed).choice(len(z), MAX_FRAMES, replace=False)]
            w, mu, var = fit_gmm(z, seed=seed)
            by_style[STYLES[sid]] = Mixture(w, mu, var, cols)
        out[sk] = by_style
    return out


def write_mixtures(library_roots: dict[str, str | Path], path: Path, seed: int = 0) -> None:
    """Fit (or take from the cache: the fit depends only on the libraries and the seed) and write."""
    import hashlib
    import json
    import shutil

    from g1_control.assets import cache_dir
    from g1_control.motion.library import MotionLibrary

    keys = {sk: MotionLibrary(root).index.get("key") for sk, root in sorted(library_roots.items())}
    blob = json.dumps({"keys": keys, "roots": {k: str(v) for k, v in sorted(library_roots.items())}, "seed": seed,
                       "k": COMPONENTS, "n": MAX_FRAMES, "v": 1}, sort_keys=True)
    cached = cache_dir() / "feedback" / f"{hashlib.sha256(blob.encode()).hexdigest()[:16]}.npz"
    if not cached.is_file():
        cached.parent.mkdir(parents=True, exist_ok=True)
        save_mixtures(fit_mixtures(library_roots, seed), cached)
    shutil.copyfile(cached, path)
