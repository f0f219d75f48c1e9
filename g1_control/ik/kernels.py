"""Compiled inner loops of the IK's per-tick path (numba).

A differential-IK tick is little arithmetic (a few 6 x 35 Jacobians, one 35-variable QP) spread
over many small operations; in Python each small numpy or pinocchio call costs about a
microsecond whatever its size, and the frame rows alone took ~100 of them per tick. Here the rows
of every frame target and foot hold are formed in one compiled call from quantities pinocchio
already computed (the world joint Jacobians `data.J` and the frames' placements).

The maths, for a frame at placement (R, p) with target (R*, p*) and joint Jacobian J (world
axes, spatial velocity at the world origin, restricted to the joints that move the frame):
    error        e = (p - p*, log3(R*^T R))
    linear rows  J_lin - [p]x J_ang          (velocity of the frame origin, world axes)
    angular rows Jlog3(R*^T R) R^T J_ang     (d log3 / d dq, the frame's own axes)
which is what `FrameTask.compute_jacobian` computes with pinocchio one call at a time; the tests
compare the two, and both against finite differences.
"""

from __future__ import annotations

import math
from typing import Any

import numba
import numpy as np

_NJIT: dict[str, Any] = {"cache": True, "nogil": True, "error_model": "numpy"}


@numba.njit(**_NJIT)
def quat_to_matrix(qw: float, qx: float, qy: float, qz: float, out: np.ndarray) -> None:
    """Unit quaternion (normalised here) -> 3x3 rotation written into out."""
    n = math.sqrt(qw * qw + qx * qx + qy * qy + qz * qz)
    w, x, y, z = qw / n, qx / n, qy / n, qz / n
    out[0, 0] = 1 - 2 * (y * y + z * z)
    out[0, 1] = 2 * (x * y - w * z)
    out[0, 2] = 2 * (x * z + w * y)
    out[1, 0] = 2 * (x * y + w * z)
    out[1, 1] = 1 - 2 * (x * x + z * z)
    out[1, 2] = 2 * (y * z - w * x)
    out[2, 0] = 2 * (x * z - w * y)
    out[2, 1] = 2 * (y * z + w * x)
    out[2, 2] = 1 - 2 * (x * x + y * y)


@numba.njit(**_NJIT)
def log3(rot: np.ndarray, out: np.ndarray) -> None:
    """Rotation vector w (angle in [0, pi]) with exp(w) = rot, written into out (3,)."""
    vx = 0.5 * (rot[2, 1] - rot[1, 2])
    vy = 0.5 * (rot[0, 2] - rot[2, 0])
    vz = 0.5 * (rot[1, 0] - rot[0, 1])  # (vx, vy, vz) = sin(angle) * axis
    s = math.sqrt(vx * vx + vy * vy + vz * vz)
    c = 0.5 * (rot[0, 0] + rot[1, 1] + rot[2, 2] - 1.0)
    angle = math.atan2(s, c)  # precise at small angles, unlike acos
    if angle < math.pi - 1e-3:
        scale = 1.0 + angle * angle / 6.0 if s < 1e-8 else angle / s
        out[0], out[1], out[2] = vx * scale, vy * scale, vz * scale
        return
    # Near pi, sin(angle) * axis is too small to carry the axis: read it from the symmetric part,
    # R + R^T = 2 cos I + 2 (1 - cos) a a^T, on its largest diagonal entry.
    k = 0
    if rot[1, 1] > rot[k, k]:
        k = 1
    if rot[2, 2] > rot[k, k]:
        k = 2
    one_minus_c = 1.0 - c
    ak = math.sqrt(max((rot[k, k] - c) / one_minus_c, 0.0))
    axis = np.empty(3)
    for i in range(3):
        axis[i] = ak if i == k else 0.5 * (rot[i, k] + rot[k, i]) / (one_minus_c * ak)
    if axis[0] * vx + axis[1] * vy + axis[2] * vz < 0.0:  # the sign comes from sin(angle) * axis
        angle = -angle
    out[0], out[1], out[2] = axis[0] * angle, axis[1] * angle, axis[2] * angle


@numba.njit(**_NJIT)
def jlog3(w: np.ndarray, out: np.ndarray) -> None:
    """d log3(R exp(d)) / d d at d = 0 for R = exp(w) (pinocchio's Jlog3), into out (3, 3):
    I + [w]x / 2 + (1/t^2 - (1 + cos t) / (2 t sin t)) [w]x^2 with t = |w|."""
    t2 = w[0] * w[0] + w[1] * w[1] + w[2] * w[2]
    t = math.sqrt(t2)
    if t < 1e-4:
        coef = 1.0 / 12.0 + t2 / 720.0
    else:
        # At t = pi, 1 + cos t vanishes faster than sin t: the clamp only avoids 0 / 0.
        coef = 1.0 / t2 - (1.0 + math.cos(t)) / (2.0 * t * max(math.sin(t), 1e-12))
    # [w]x^2 = w w^T - t^2 I
    for i in range(3):
        for j in range(3):
            out[i, j] = coef * (w[i] * w[j] - (t2 if i == j else 0.0))
        out[i, i] += 1.0
    out[0, 1] -= 0.5 * w[2]
    out[0, 2] += 0.5 * w[1]
    out[1, 0] += 0.5 * w[2]
    out[1, 2] -= 0.5 * w[0]
    out[2, 0] -= 0.5 * w[1]
    out[2, 1] += 0.5 * w[0]


@numba.njit(**_NJIT)
def frame_rows(joint_jacobians: np.ndarray, placements: np.ndarray, targets: np.ndarray, masks: np.ndarray,
               orientation: np.ndarray, row_start: np.ndarray, jac_out: np.ndarray, err_out: np.ndarray) -> None:
    """Rows of K frame targets.

    joint_jacobians (6, nv): pinocchio's data.J after computeJointJacobians (world axes).
    placements (K, 4, 4): the frames' world placements. targets (K, 7): x y z qw qx qy qz.
    masks (K, nv): 1 where the velocity moves the frame (its joint's support), else 0.
    orientation (K,): False for position-only frames (3 rows, no rotation error).
    Frame k writes rows row_start[k] .. +3 (or +6) of jac_out (m, nv) and err_out (m,).
    """
    nv = joint_jacobians.shape[1]
    rt = np.empty((3, 3))
    rel = np.empty((3, 3))
    w = np.empty(3)
    jl = np.empty((3, 3))
    m = np.empty((3, 3))
    for k in range(placements.shape[0]):
        r0 = row_start[k]
        px, py, pz = placements[k, 0, 3], placements[k, 1, 3], placements[k, 2, 3]
        err_out[r0] = px - targets[k, 0]
        err_out[r0 + 1] = py - targets[k, 1]
        err_out[r0 + 2] = pz - targets[k, 2]
        for j in range(nv):
            mk = masks[k, j]
            jx, jy, jz = joint_jacobians[3, j], joint_jacobians[4, j], joint_jacobians[5, j]
            jac_out[r0, j] = mk * (joint_jacobians[0, j] - (py * jz - pz * jy))
            jac_out[r0 + 1, j] = mk * (joint_jacobians[1, j] - (pz * jx - px * jz))
            jac_out[r0 + 2, j] = mk * (joint_jacobians[2, j] - (px * jy - py * jx))
        if not orientation[k]:
            continue
        quat_to_matrix(targets[k, 3], targets[k, 4], targets[k, 5], targets[k, 6], rt)
        for a in range(3):
            for b in range(3):
                rel[a, b] = rt[0, a] * placements[k, 0, b] + rt[1, a] * placements[k, 1, b] \
                    + rt[2, a] * placements[k, 2, b]
        log3(rel, w)
        err_out[r0 + 3] = w[0]
        err_out[r0 + 4] = w[1]
        err_out[r0 + 5] = w[2]
        jlog3(w, jl)
        for a in range(3):  # m = Jlog3 R^T
            for b in range(3):
                m[a, b] = jl[a, 0] * placements[k, b, 0] + jl[a, 1] * placements[k, b, 1] \
                    + jl[a, 2] * placements[k, b, 2]
        for j in range(nv):
            mk = masks[k, j]
            jx, jy, jz = joint_jacobians[3, j], joint_jacobians[4, j], joint_jacobians[5, j]
            for a in range(3):
                jac_out[r0 + 3 + a, j] = mk * (m[a, 0] * jx + m[a, 1] * jy + m[a, 2] * jz)


def warm_up() -> None:
    """Compile (or load from numba's cache) the kernels with the argument types the IK passes,
    so the first control tick does not pay for it (~0.3 s cached, ~2 s compiled)."""
    nv = 35
    rows = np.empty((6, nv))
    frame_rows(np.zeros((6, nv)), np.eye(4)[None].copy(), np.array([[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0]]),
               np.ones((1, nv)), np.array([True]), np.zeros(1, dtype=np.int64), rows, np.empty(6))
