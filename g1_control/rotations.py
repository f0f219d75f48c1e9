"""Rotations, in one place: quaternions in (w, x, y, z) order (the project's convention), rotation
matrices, roll-pitch-yaw, the heading (yaw) frame.

The array functions take (..., 4) quaternions or (..., 3, 3) matrices. The scalar ones
(`quat_to_rot`, `yaw_of`, `tilt_rad`, `projected_gravity`) take one quaternion and run every
control tick, so they are written out instead of broadcast, on Python floats (a numpy scalar
operation costs ~20 times a float one; tests/test_rotations.py holds them to the array versions). The IK's compiled per-tick copies
(g1_control/ik/kernels.py) are tested against pinocchio.

Frames: "_w" world; "_b" base (pelvis); "_h" heading: the world frame turned by the base's yaw,
so x points forward along the ground, y left, z up.
"""

from __future__ import annotations

import math

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


# -- single rotations, per control tick ---------------------------------------------------------------------
def _floats(quat_wxyz) -> list[float]:
    return np.asarray(quat_wxyz, dtype=float).tolist()


def quat_to_rot_rows(quat_wxyz) -> list[list[float]]:
    """quat_to_rot as three rows of Python floats (for per-tick arithmetic on 3-vectors)."""
    w, x, y, z = _floats(quat_wxyz)
    return [
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
    ]


def quat_to_rot(quat_wxyz: np.ndarray) -> np.ndarray:
    """(3, 3) rotation matrix (body -> world) of one unit quaternion."""
    return np.array(quat_to_rot_rows(quat_wxyz))


def yaw_of(quat_wxyz: np.ndarray) -> float:
    """Heading (rad): the yaw of the ZYX roll-pitch-yaw decomposition."""
    w, x, y, z = _floats(quat_wxyz)
    return math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))


def tilt_rad(quat_wxyz: np.ndarray) -> float:
    """Angle between the body z axis and world up."""
    w, x, y, z = _floats(quat_wxyz)
    norm = math.sqrt(w * w + x * x + y * y + z * z)
    if norm == 0.0:
        return math.nan
    x, y = x / norm, y / norm
    cos = 1.0 - 2.0 * (x * x + y * y)
    cos = 1.0 if cos > 1.0 else -1.0 if cos < -1.0 else cos  # NaN stays NaN
    return math.acos(cos)


def projected_gravity(quat_wxyz: np.ndarray) -> np.ndarray:
    """World gravity direction (0, 0, -1) expressed in the body frame of `quat_wxyz`."""
    w, x, y, z = _floats(quat_wxyz)
    # Third row of R (body->world), negated: R^T @ (0, 0, -1).
    return np.array([-(2 * (x * z - w * y)), -(2 * (y * z + w * x)), -(1 - 2 * (x * x + y * y))])


def rotation_error(rot_ref: np.ndarray, rot: np.ndarray) -> np.ndarray:
    """World-frame rotation vector taking `rot` to `rot_ref` (log map of rot_ref rot^T)."""
    r = rot_ref @ rot.T
    cos = min(max((r[0, 0] + r[1, 1] + r[2, 2] - 1.0) / 2.0, -1.0), 1.0)  # min/max: np.clip costs ~10 us on a scalar
    angle = np.arccos(cos)
    axis_sin = np.array([r[2, 1] - r[1, 2], r[0, 2] - r[2, 0], r[1, 0] - r[0, 1]]) / 2.0
    if angle < 1e-6:
        return axis_sin
    sin = np.sin(angle)
    if sin < 1e-6:  # angle near pi: pick the axis from the diagonal
        axis = np.sqrt(np.maximum((np.diag(r) + 1.0) / 2.0, 0.0))
        k = int(np.argmax(axis))
        axis = np.sign(r[k] + r[:, k]) * axis if axis[k] > 0 else axis
        return angle * axis / np.linalg.norm(axis)
    return axis_sin * (angle / sin)


# -- roll, pitch, yaw (ZYX) -----------------------------------------------------------------------------------
def rpy_to_rot(rpy: np.ndarray) -> np.ndarray:
    r, p, y = rpy
    cr, sr, cp, sp, cy, sy = np.cos(r), np.sin(r), np.cos(p), np.sin(p), np.cos(y), np.sin(y)
    return np.array([[cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
                     [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
                     [-sp, cp * sr, cp * cr]])


def rot_to_rpy(rot: np.ndarray) -> np.ndarray:
    return np.array([np.arctan2(rot[2, 1], rot[2, 2]), -np.arcsin(np.clip(rot[2, 0], -1, 1)),
                     np.arctan2(rot[1, 0], rot[0, 0])])


def rpy_to_quat(rpy: np.ndarray) -> np.ndarray:
    r, p, y = np.asarray(rpy, dtype=float) / 2
    cr, sr, cp, sp, cy, sy = np.cos(r), np.sin(r), np.cos(p), np.sin(p), np.cos(y), np.sin(y)
    return np.array([cr * cp * cy + sr * sp * sy, sr * cp * cy - cr * sp * sy,
                     cr * sp * cy + sr * cp * sy, cr * cp * sy - sr * sp * cy])


# -- the heading frame ----------------------------------------------------------------------------------------
def yaw_of_matrix(rot: np.ndarray) -> np.ndarray:
    """Heading (rad) of rotation matrices (..., 3, 3): the body x axis projected on the ground."""
    return np.arctan2(rot[..., 1, 0], rot[..., 0, 0])


def rot_z(yaw: np.ndarray) -> np.ndarray:
    """(..., 3, 3) rotations about world z by `yaw` (heading -> world)."""
    c, s = np.cos(yaw), np.sin(yaw)
    out = np.zeros(np.shape(yaw) + (3, 3))
    out[..., 0, 0], out[..., 0, 1], out[..., 1, 0], out[..., 1, 1], out[..., 2, 2] = c, -s, s, c, 1.0
    return out


def world_to_heading(vec_w: np.ndarray, yaw_rad: float) -> np.ndarray:
    """A world-frame 3-vector in the heading frame of `yaw_rad`."""
    c, s = np.cos(yaw_rad), np.sin(yaw_rad)
    return np.array([c * vec_w[0] + s * vec_w[1], -s * vec_w[0] + c * vec_w[1], vec_w[2]])


def heading_to_world(vec_h: np.ndarray, yaw_rad: float) -> np.ndarray:
    """A heading-frame 3-vector in the world frame."""
    c, s = np.cos(yaw_rad), np.sin(yaw_rad)
    return np.array([c * vec_h[0] - s * vec_h[1], s * vec_h[0] + c * vec_h[1], vec_h[2]])


def wrap_angle(angle_rad):
    """Angle(s) wrapped into [-pi, pi)."""
    return (np.asarray(angle_rad) + np.pi) % (2 * np.pi) - np.pi
