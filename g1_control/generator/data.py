"""Reading a built motion library as generator features (any variant): where each variant's
library lives, and the per-clip (T, D) feature arrays with style ids. Runtime-safe (numpy only);
training, benches and the motion-matching baseline all read through here."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from g1_control.generator import features as F

FINGER_SUFFIX = ".fingers.npy"
"""Finger angles of a clip of the G1-with-hands library: clips/<name>.fingers.npy, (T, 14)."""


def library_dir(variant: str = "g1_29dof") -> Path:
    """Default folder of a variant's library (the 29-DoF one is `g1 library build`'s)."""
    from g1_control.assets import cache_dir

    return cache_dir() / ("library" if variant == "g1_29dof" else f"library_{variant}")


def finger_path(library_root: str | Path, entry_file: str) -> Path:
    return Path(library_root) / (entry_file.removesuffix(".npz") + FINGER_SUFFIX)


def library_variant(lib) -> str:
    return str(lib.index.get("variant", "g1_29dof"))


def load_split(library_root: str | Path | None, split: str, variant: str | None = None,
               with_entries: bool = False):
    """(features per clip [(T, D)], style ids) of one split; `variant` picks the default folder when
    library_root is None. with_entries adds the ClipEntry list."""
    from g1_control.generator.styles import style_id
    from g1_control.motion.library import MotionLibrary

    lib = MotionLibrary(library_root or library_dir(variant or "g1_29dof"))
    entries = lib.select(split)
    feats, styles = [], []
    for e in entries:
        clip = lib.load(e)
        path = finger_path(lib.root, e.file)
        fingers = np.load(path).astype(float) if path.is_file() else None
        feats.append(F.clip_features(clip, fingers))
        styles.append(style_id(clip.style))
    return (feats, styles, entries) if with_entries else (feats, styles)
