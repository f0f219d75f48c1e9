"""The in-betweening interface every method (baselines and the learned backbone) implements,
so one harness evaluates them all and the runtime can swap them.

All arrays are in the canonical frame of the last context frame (features.py). The target's
mask says which of its D features are given: all (full pose), the root only, chosen joints or
effector positions (COMET-style partial keyframes); the method fills everything else.
"""

from __future__ import annotations

from abc import ABC, abstractmethod

import numpy as np

from g1_control.generator import features as F

CONTEXT_FRAMES = 10
"""Context length of the evaluation protocol (Harvey et al. 2020) and of the backbone."""
MAX_GAP = 30


class InbetweenError(ValueError):
    """Bad input to an in-betweener."""


class Inbetweener(ABC):
    name: str = "inbetweener"

    @abstractmethod
    def infill(self, context: np.ndarray, target: np.ndarray, target_mask: np.ndarray, gap: int,
               style: np.ndarray) -> np.ndarray:
        """context (B, C, D), target (B, D), target_mask (B, D) bool, style (B,) ints -> (B, gap, D)."""

    @staticmethod
    def check(context: np.ndarray, target: np.ndarray, target_mask: np.ndarray, gap: int, style: np.ndarray) -> None:
        if context.ndim != 3 or context.shape[2] != F.DIM or context.shape[1] < 2:
            raise InbetweenError(f"context must have shape (B, C>=2, {F.DIM}); got {context.shape}")
        b = context.shape[0]
        if target.shape != (b, F.DIM) or target_mask.shape != (b, F.DIM):
            raise InbetweenError(f"target and target_mask must have shape ({b}, {F.DIM}); got {target.shape} "
                                 f"and {target_mask.shape}")
        if not 1 <= gap <= MAX_GAP:
            raise InbetweenError(f"gap must be 1..{MAX_GAP} frames; got {gap}")
        if np.shape(style) != (b,):
            raise InbetweenError(f"style must have shape ({b},); got {np.shape(style)}")
        if not (np.isfinite(context).all() and np.isfinite(np.where(target_mask, target, 0.0)).all()):
            raise InbetweenError("context or the given target features contain NaN or inf")


def fill_target(context_last: np.ndarray, target: np.ndarray, target_mask: np.ndarray, gap: int) -> np.ndarray:
    """A complete target where only some features are given: given ones win, missing ones hold
    the last context frame's value."""
    return np.where(target_mask, target, context_last)


def interpolate(context_last: np.ndarray, target_full: np.ndarray, gap: int) -> np.ndarray:
    """Linear interpolation of features (joints are 1-DoF rotations, so this is slerp per joint;
    the root rotation's 6D columns are re-orthonormalized)."""
    alpha = (np.arange(1, gap + 1) / (gap + 1))[None, :, None]
    out = context_last[:, None, :] * (1 - alpha) + target_full[:, None, :] * alpha
    rot = F.rot6d_to_matrix(out[..., F.ROOT_ROT])
    out[..., 3:6], out[..., 6:9] = rot[..., :, 0], rot[..., :, 1]
    return out
