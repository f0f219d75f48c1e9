"""Resampling of sampled trajectories: times at a new rate, linear interpolation of positions,
slerp of orientations (used by clips, object tracks, rollouts and the retargeter)."""

from __future__ import annotations

import numpy as np

from g1_control import rotations as quat


def resample_times(num_frames: int, fps: float, new_fps: float) -> np.ndarray:
    """Sample times (s) at new_fps covering [0, duration] of a clip of num_frames at fps."""
    duration = (num_frames - 1) / fps
    # Frame times in files are rounded (BVH "0.0333333"): a last sample within 1e-4 of a frame
    # period of the end still counts, else 30 -> 30 fps would drop the last frame.
    count = int(np.floor(duration * new_fps + 1e-4)) + 1
    return np.arange(count) / new_fps


def interpolate_positions(values: np.ndarray, fps: float, times_s: np.ndarray) -> np.ndarray:
    """Linear interpolation of (T, ...) samples at frame rate fps, at times_s."""
    src = np.arange(values.shape[0]) / fps
    flat = values.reshape(values.shape[0], -1)
    out = np.empty((times_s.shape[0], flat.shape[1]))
    for c in range(flat.shape[1]):
        out[:, c] = np.interp(times_s, src, flat[:, c])
    return out.reshape((times_s.shape[0],) + values.shape[1:])


def interpolate_quaternions(quats: np.ndarray, fps: float, times_s: np.ndarray) -> np.ndarray:
    """Slerp of (T, ..., 4) orientations at times_s."""
    pos = np.clip(times_s * fps, 0.0, quats.shape[0] - 1)
    lo = np.floor(pos).astype(int)
    hi = np.minimum(lo + 1, quats.shape[0] - 1)
    frac = pos - lo
    frac = frac.reshape(frac.shape + (1,) * (quats.ndim - 2))
    return quat.slerp(quats[lo], quats[hi], frac)
