"""Reference-guided feedback (after COMET): each generated pose is attracted back toward the
library's poses of the current style, so an autoregressive rollout cannot drift off the pose
manifold (a sagging waist, arms creeping away), while poses the library supports are left alone.

The reference is a Gaussian mixture per (skeleton, style) with diagonal covariances, fitted on the
library's training frames (training/mixtures.py, shipped as feedback.npz next to the model) over
the pose features that drift: pelvis height, the waist and arm joints the skeleton has, and its
fingers. The legs are left out: their pose is the gait, tied to the root path and the feet.

Per frame, with responsibilities r_k of the components and each component's normalized
Mahalanobis distance d_k (RMS over dimensions of (z - mu_k) / sigma_k), the pose moves by
    w * sum_k r_k * max(0, 1 - tau / d_k) * (mu_k - z)
i.e. a pose within tau standard deviations of its component is untouched and one beyond is pulled
back toward it, by `strength` w per plan. The weight fades to 0 near a goal: in time (frames
within `fade_frames` of a goal's frame or of the target keyframe) and in space (an effector with a
goal within near_m of it), so the feedback never fights what the operator asked for.
The mixture is switched per style at run time (set_style), and a whole set can be swapped
(set_mixtures), e.g. after refitting on a rebuilt library.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from g1_control.generator import features as F
from g1_control.generator import skeleton as S
from g1_control.robot import g1


def feedback_columns(skeleton: str) -> np.ndarray:
    """Feature indices the feedback covers on a skeleton: pelvis height, present waist/arm joints,
    present fingers."""
    sk = S.skeleton(skeleton)
    slots = [j for j in g1.UPPER_BODY_JOINTS if sk.present[j]] + [
        S.NUM_BODY + k for k in range(S.NUM_FINGERS) if sk.present[S.NUM_BODY + k]]
    return np.r_[[2], F.JOINT_SLOTS[slots]].astype(int)


@dataclass
class Mixture:
    weights: np.ndarray
    """(K,)"""
    means: np.ndarray
    """(K, d)"""
    variances: np.ndarray
    """(K, d)"""
    columns: np.ndarray
    """(d,) feature indices (feedback_columns)."""

    def responsibilities(self, z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """z (N, d) -> responsibilities (N, K) and normalized Mahalanobis distances (N, K)."""
        diff = z[:, None, :] - self.means[None]
        m2 = (diff * diff / self.variances[None]).sum(-1)
        logp = np.log(self.weights)[None] - 0.5 * m2 - 0.5 * np.log(self.variances).sum(-1)[None]
        logp -= logp.max(axis=1, keepdims=True)
        r = np.exp(logp)
        r /= r.sum(axis=1, keepdims=True)
        return r, np.sqrt(m2 / z.shape[1])


def save_mixtures(mixtures: dict[str, dict[str, Mixture]], path: Path) -> None:
    blob = {}
    for sk, by_style in mixtures.items():
        for style, m in by_style.items():
            for field in ("weights", "means", "variances", "columns"):
                blob[f"{sk}/{style}/{field}"] = getattr(m, field)
    np.savez_compressed(path, **blob)


def load_mixtures(path: str | Path, skeleton: str) -> dict[str, Mixture]:
    data = np.load(path)
    parts: dict[str, dict] = {}
    for key in data.files:
        sk, style, field = key.split("/")
        if sk == skeleton:
            parts.setdefault(style, {})[field] = data[key]
    return {style: Mixture(**p) for style, p in parts.items()}


class ReferenceFeedback:
    def __init__(self, mixtures: dict[str, Mixture], strength: float = 0.5, tau: float = 1.5,
                 fade_frames: int = 8, near_m: tuple[float, float] = (0.10, 0.35)):
        self.mixtures = mixtures
        self.strength = strength
        self.tau = tau
        self.fade_frames = fade_frames
        self.near_m = near_m
        self.style = "default"

    @classmethod
    def load(cls, path: str | Path, skeleton: str, **kwargs) -> ReferenceFeedback:
        return cls(load_mixtures(path, skeleton), **kwargs)

    def set_style(self, style: str) -> None:
        """Switch the reference to a style's mixture (the default style's when it has none)."""
        self.style = style

    def set_mixtures(self, mixtures: dict[str, Mixture]) -> None:
        self.mixtures = mixtures

    @property
    def mixture(self) -> Mixture | None:
        return self.mixtures.get(self.style) or self.mixtures.get("default")

    def frame_weights(self, n: int, goal_frames: Sequence[int] = (), target_frame: int | None = None,
                      frames: np.ndarray | None = None,
                      effector_goals: Sequence[tuple[slice, np.ndarray]] = ()) -> np.ndarray:
        """(n,) feedback weight per frame: `strength`, faded near goals in time (frame indices,
        0-based; the target keyframe at `target_frame`) and in space (effector columns, goal point)."""
        w = np.full(n, self.strength)
        k = np.arange(n)
        for gf in list(goal_frames) + ([target_frame] if target_frame is not None else []):
            w *= np.clip(np.abs(k - gf) / self.fade_frames, 0.0, 1.0)
        if frames is not None:
            lo, hi = self.near_m
            for cols, point in effector_goals:
                d = np.linalg.norm(frames[:, cols] - point, axis=-1)
                w *= np.clip((d - lo) / (hi - lo), 0.0, 1.0)
        return w

    def apply(self, frames: np.ndarray, weights: np.ndarray) -> np.ndarray:
        """frames (n, D) (any planar frame: the covered features are frame-invariant) -> corrected."""
        m = self.mixture
        if m is None or not np.any(weights > 0):
            return frames
        z = frames[:, m.columns]
        r, d = m.responsibilities(z)
        pull = r * np.maximum(0.0, 1.0 - self.tau / np.maximum(d, 1e-9))  # (n, K)
        step = pull @ m.means - pull.sum(axis=1, keepdims=True) * z
        out = frames.copy()
        out[:, m.columns] = z + weights[:, None] * step
        return out

    def distance(self, frames: np.ndarray) -> np.ndarray:
        """Per frame: normalized Mahalanobis distance to the nearest component (the drift measure)."""
        m = self.mixture
        if m is None:
            raise ValueError("no reference mixture for this style (nor a default one)")
        _, d = m.responsibilities(frames[:, m.columns])
        return d.min(axis=1)


class FeedbackInbetweener:
    """Any Inbetweener with the feedback applied to its frames (faded toward the target keyframe,
    which is a goal): the "backbone + feedback" row of the benchmark."""

    def __init__(self, inner, feedback: ReferenceFeedback, name: str | None = None):
        self.inner = inner
        self.feedback = feedback
        self.name = name or f"{inner.name}+feedback"

    def set_goals(self, goal, mask) -> None:
        self.inner.set_goals(goal, mask)

    def infill(self, context, target, target_mask, gap, style):
        from g1_control.generator.styles import STYLES

        frames = self.inner.infill(context, target, target_mask, gap, style)
        w = self.feedback.frame_weights(gap, target_frame=gap)
        out = np.empty_like(frames)
        for i in range(len(frames)):
            sid = int(style[i])
            self.feedback.set_style(STYLES[sid] if sid < len(STYLES) else "default")
            out[i] = self.feedback.apply(frames[i], w)
        return out
