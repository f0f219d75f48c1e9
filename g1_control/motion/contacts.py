"""Foot contact labels from foot motion: a foot is in stance when it is slow and low.

Used for clips that carry no labels (G1 CSV, foreign npz) and for human mocap before
retargeting. Thresholds are in SI units at the clip's own scale.
"""

from __future__ import annotations

import numpy as np


def stance_from_trajectory(pos_w_m: np.ndarray, fps: float, max_speed_mps: float = 0.3,
                           max_height_above_lowest_m: float | None = None, min_frames: int = 2) -> np.ndarray:
    """(T,) bool stance labels for one foot point (T, 3).

    Slow = speed below max_speed_mps (central differences). With max_height_above_lowest_m the
    point must also be within that of its lowest height in the clip (flat-ground clips; leave
    None where the foot may rest on raised terrain). Stance runs shorter than min_frames are dropped
    (a swing foot passing through zero speed is not a contact).
    """
    pos = np.asarray(pos_w_m, dtype=float)
    if pos.shape[0] < 2:
        return np.ones(pos.shape[0], dtype=bool)
    vel = np.gradient(pos, 1.0 / fps, axis=0)
    stance = np.linalg.norm(vel, axis=-1) < max_speed_mps
    if max_height_above_lowest_m is not None:
        stance &= pos[:, 2] < pos[:, 2].min() + max_height_above_lowest_m
    if min_frames > 1:
        stance = drop_short_runs(stance, min_frames)
    return stance


def drop_short_runs(mask: np.ndarray, min_len: int) -> np.ndarray:
    """`mask` with its runs of True shorter than min_len set False."""
    out = mask.copy()
    start = None
    for i, v in enumerate(np.append(mask, False)):
        if v and start is None:
            start = i
        elif not v and start is not None:
            if i - start < min_len:
                out[start:i] = False
            start = None
    return out


def foot_contacts(foot_pos_w_m: np.ndarray, fps: float, max_speed_mps: float = 0.3,
                  max_height_m: float = 0.08) -> np.ndarray:
    """(T, 2) labels for (left, right) foot positions (T, 2, 3) of a robot clip on flat ground:
    slow and within max_height_m of the ground (z = 0)."""
    labels = np.zeros(foot_pos_w_m.shape[:2], dtype=bool)
    for side in range(2):
        stance = stance_from_trajectory(foot_pos_w_m[:, side], fps, max_speed_mps)
        labels[:, side] = stance & (foot_pos_w_m[:, side, 2] < max_height_m)
    return labels
