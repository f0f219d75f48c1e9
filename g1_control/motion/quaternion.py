"""Quaternion helpers on (..., 4) arrays in (w, x, y, z) order, the project's convention."""

from __future__ import annotations

import numpy as np


def normalize(q: np.ndarray) -> np.ndarray:
    return q / np.linalg.norm(q, axis=-1, keepdims=True)


def conjugate(q: np.ndarray) -> np.ndarray:
    return q * np.array([1.0, -1.0, -1.0, -1.0])


def multiply(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    aw, ax, ay, az = np.moveaxis(a, -1, 0)
    bw, bx, by, bz = np.moveaxis(b, -1, 0)
    return np.stack([aw * bw - ax * bx - ay * by - az * bz,
                     aw * bx + ax * bw + ay * bz - az * by,
                     aw * by - ax * bz + ay * bw + az * bx,
                     aw * bz + ax * by - ay * bx + az * bw], axis=-1)


def to_matrix(q: np.ndarray) -> np.ndarray:
    w, x, y, z = np.moveaxis(normalize(q), -1, 0)
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], axis=-1),
        np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], axis=-1),
        np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], axis=-1),
    ], axis=-2)


def from_matrix(m: np.ndarray) -> np.ndarray:
    """(..., 3, 3) rotation matrices -> (..., 4) quaternions with w >= 0."""
    from scipy.spatial.transform import Rotation

    m = np.asarray(m, dtype=float)
    out = Rotation.from_matrix(m.reshape(-1, 3, 3)).as_quat(scalar_first=True)
    out[out[:, 0] < 0] *= -1
    return out.reshape(m.shape[:-2] + (4,))


def slerp(a: np.ndarray, b: np.ndarray, t: np.ndarray | float) -> np.ndarray:
    """Spherical interpolation from a to b at fraction t (broadcast), along the shorter arc."""
    a, b = normalize(np.asarray(a, dtype=float)), normalize(np.asarray(b, dtype=float))
    t = np.asarray(t, dtype=float)[..., None] if np.ndim(t) else float(t)
    dot = np.sum(a * b, axis=-1, keepdims=True)
    b = np.where(dot < 0, -b, b)
    dot = np.abs(dot)
    theta = np.arccos(np.clip(dot, -1.0, 1.0))
    sin_theta = np.sin(theta)
    small = sin_theta < 1e-8
    safe = np.where(small, 1.0, sin_theta)
    wa = np.where(small, 1.0 - t, np.sin((1.0 - t) * theta) / safe)
    wb = np.where(small, t, np.sin(t * theta) / safe)
    return normalize(wa * a + wb * b)


def to_rotvec(q: np.ndarray) -> np.ndarray:
    """Axis * angle (rad) of each quaternion, angle in [0, pi]."""
    q = normalize(q)
    q = np.where(q[..., :1] < 0, -q, q)
    vec = q[..., 1:]
    sin_half = np.linalg.norm(vec, axis=-1, keepdims=True)
    angle = 2.0 * np.arctan2(sin_half, q[..., :1])
    scale = np.where(sin_half > 1e-12, angle / np.where(sin_half > 1e-12, sin_half, 1.0), 2.0)
    return vec * scale


def angular_velocity_w(quats: np.ndarray, fps: float) -> np.ndarray:
    """World-frame angular velocity (rad/s) from consecutive orientations (T, ..., 4), by central
    differences inside and one-sided at the ends."""
    t = quats.shape[0]
    out = np.zeros(quats.shape[:-1] + (3,))
    if t < 2:
        return out
    # q_{k+1} = dq * q_k with dq in the world frame: dq = q_{k+1} q_k^*
    fwd = to_rotvec(multiply(quats[1:], conjugate(quats[:-1]))) * fps
    out[0] = fwd[0]
    out[-1] = fwd[-1]
    if t > 2:
        out[1:-1] = 0.5 * (fwd[1:] + fwd[:-1])
    return out
