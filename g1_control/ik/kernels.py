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


# ---------------------------------------------------------------------------- collision geometry
@numba.njit(**_NJIT)
def joint_placements(q: np.ndarray, parents: np.ndarray, place_rot: np.ndarray, place_pos: np.ndarray,
                     axes: np.ndarray, rot_out: np.ndarray, pos_out: np.ndarray) -> None:
    """World rotation (J, 3, 3) and position (J, 3) of every joint frame of a pinocchio model made of
    a free-flyer (joint 1: q[0:3], quaternion q[3:7] x y z w) and revolute joints about their own x,
    y or z axis (axes[k] = 0, 1, 2; joint k >= 2 reads q[5 + k]); joint 0 is the world. What
    pinocchio's forwardKinematics puts in data.oMi, in one compiled pass (the tests compare)."""
    rot_out[0] = np.eye(3)
    pos_out[0] = 0.0
    local = np.empty((3, 3))
    spin = np.empty((3, 3))
    for k in range(1, parents.shape[0]):
        p = parents[k]
        if k == 1:
            quat_to_matrix(q[6], q[3], q[4], q[5], local)
            for i in range(3):
                pos_out[1, i] = q[i]
                for j in range(3):
                    rot_out[1, i, j] = local[i, j]
            continue
        c, s = math.cos(q[5 + k]), math.sin(q[5 + k])
        a = axes[k]
        for i in range(3):
            for j in range(3):
                spin[i, j] = 1.0 if i == j else 0.0
        i1, i2 = (a + 1) % 3, (a + 2) % 3
        spin[i1, i1], spin[i1, i2], spin[i2, i1], spin[i2, i2] = c, -s, s, c
        for i in range(3):  # local = place_rot[k] @ spin
            for j in range(3):
                local[i, j] = place_rot[k, i, 0] * spin[0, j] + place_rot[k, i, 1] * spin[1, j] \
                    + place_rot[k, i, 2] * spin[2, j]
        for i in range(3):
            pos_out[k, i] = pos_out[p, i] + rot_out[p, i, 0] * place_pos[k, 0] + rot_out[p, i, 1] * place_pos[k, 1] \
                + rot_out[p, i, 2] * place_pos[k, 2]
            for j in range(3):
                rot_out[k, i, j] = rot_out[p, i, 0] * local[0, j] + rot_out[p, i, 1] * local[1, j] \
                    + rot_out[p, i, 2] * local[2, j]


@numba.njit(**_NJIT)
def _segment_distance(ends: np.ndarray, a: int, b: int) -> float:
    """Distance between segments ends[a] and ends[b] ((2, 3) each), from their closest points
    (clamped segment parameters; scalar arithmetic: no temporary arrays in the pair loop)."""
    px, py, pz = ends[a, 0, 0], ends[a, 0, 1], ends[a, 0, 2]
    qx, qy, qz = ends[b, 0, 0], ends[b, 0, 1], ends[b, 0, 2]
    ux, uy, uz = ends[a, 1, 0] - px, ends[a, 1, 1] - py, ends[a, 1, 2] - pz
    vx, vy, vz = ends[b, 1, 0] - qx, ends[b, 1, 1] - qy, ends[b, 1, 2] - qz
    rx, ry, rz = px - qx, py - qy, pz - qz
    aa = ux * ux + uy * uy + uz * uz
    ee = vx * vx + vy * vy + vz * vz
    f = vx * rx + vy * ry + vz * rz
    if aa <= 1e-12 and ee <= 1e-12:
        s = t = 0.0
    elif aa <= 1e-12:
        s = 0.0
        t = min(max(f / ee, 0.0), 1.0)
    else:
        c = ux * rx + uy * ry + uz * rz
        if ee <= 1e-12:
            t = 0.0
            s = min(max(-c / aa, 0.0), 1.0)
        else:
            bb = ux * vx + uy * vy + uz * vz
            denom = aa * ee - bb * bb
            s = min(max((bb * f - c * ee) / denom, 0.0), 1.0) if denom > 1e-12 else 0.0
            t = (bb * s + f) / ee
            if t < 0.0:
                t = 0.0
                s = min(max(-c / aa, 0.0), 1.0)
            elif t > 1.0:
                t = 1.0
                s = min(max((bb - c) / aa, 0.0), 1.0)
    dx = rx + s * ux - t * vx
    dy = ry + s * uy - t * vy
    dz = rz + s * uz - t * vz
    return math.sqrt(dx * dx + dy * dy + dz * dz)


@numba.njit(**_NJIT)
def _plane_max(planes: np.ndarray, start: int, stop: int, x: float, y: float, z: float) -> float:
    top = -1e30
    for i in range(start, stop):
        top = max(top, planes[i, 0] * x + planes[i, 1] * y + planes[i, 2] * z + planes[i, 3])
    return top


@numba.njit(**_NJIT)
def _segment_polytope_gap(ends: np.ndarray, g: int, planes: np.ndarray, start: int, stop: int) -> float:
    """min over segment ends[g] of max_i (n_i . x + d_i) over planes[start:stop]: a lower bound of
    the segment's distance to that convex polytope (exact inside it and over its faces). Convex and
    piecewise linear along the segment, so its minimum is at an end or where two planes cross."""
    px, py, pz = ends[g, 0, 0], ends[g, 0, 1], ends[g, 0, 2]
    ux, uy, uz = ends[g, 1, 0] - px, ends[g, 1, 1] - py, ends[g, 1, 2] - pz
    best = min(_plane_max(planes, start, stop, px, py, pz),
               _plane_max(planes, start, stop, px + ux, py + uy, pz + uz))
    for k in range(start, stop):
        vk = planes[k, 0] * px + planes[k, 1] * py + planes[k, 2] * pz + planes[k, 3]
        dk = planes[k, 0] * ux + planes[k, 1] * uy + planes[k, 2] * uz
        for j in range(k + 1, stop):
            vj = planes[j, 0] * px + planes[j, 1] * py + planes[j, 2] * pz + planes[j, 3]
            dj = planes[j, 0] * ux + planes[j, 1] * uy + planes[j, 2] * uz
            if abs(dk - dj) < 1e-12:
                continue
            s = (vj - vk) / (dk - dj)
            if 0.0 < s < 1.0:
                best = min(best, _plane_max(planes, start, stop, px + s * ux, py + s * uy, pz + s * uz))
    return best


@numba.njit(**_NJIT)
def capsule_gaps(joint_rot: np.ndarray, joint_pos: np.ndarray, geom_joint: np.ndarray, cap_ends: np.ndarray,
                 cap_radius: np.ndarray, pair_a: np.ndarray, pair_b: np.ndarray, pair_shape: np.ndarray,
                 planes: np.ndarray, plane_start: np.ndarray, ends_out: np.ndarray, out: np.ndarray) -> None:
    """Lower bounds of the gap of each geometry pair from the geometries' bounding capsules.

    Geometry g's capsule: ends cap_ends[g] (2, 3) in its joint's frame, radius cap_radius[g].
    Pair k: geometry pair_a[k] against geometry pair_b[k] when pair_shape[k] < 0, else against
    static convex shape pair_shape[k], whose planes (n, d: inside where n . x + d <= 0) are rows
    plane_start[s] .. plane_start[s + 1] of `planes` (a floor is the one plane (0, 0, -1, h)).
    World capsule ends go to ends_out (G, 2, 3)."""
    for g in range(geom_joint.shape[0]):
        j = geom_joint[g]
        for e in range(2):
            for i in range(3):
                ends_out[g, e, i] = joint_pos[j, i] + joint_rot[j, i, 0] * cap_ends[g, e, 0] \
                    + joint_rot[j, i, 1] * cap_ends[g, e, 1] + joint_rot[j, i, 2] * cap_ends[g, e, 2]
    for k in range(pair_a.shape[0]):
        a = pair_a[k]
        s = pair_shape[k]
        if s < 0:
            b = pair_b[k]
            out[k] = _segment_distance(ends_out, a, b) - cap_radius[a] - cap_radius[b]
        else:
            out[k] = _segment_polytope_gap(ends_out, a, planes, plane_start[s], plane_start[s + 1]) - cap_radius[a]


@numba.njit(**_NJIT)
def witness_rows(joint_jacobians: np.ndarray, masks: np.ndarray, point_a: np.ndarray, mask_a: np.ndarray,
                 point_b: np.ndarray, mask_b: np.ndarray, normal: np.ndarray, rows_out: np.ndarray) -> None:
    """Row k = d/d dq of the signed distance n_k . (p_b - p_a) between two points fixed to bodies:
    n^T (J_b(p_b) - J_a(p_a)), with J(p) = J_lin - [p]x J_ang of pinocchio's data.J restricted by
    masks[m] (the coordinates that move the body; mask index -1: a static body, J = 0)."""
    nv = joint_jacobians.shape[1]
    for k in range(point_a.shape[0]):
        n0, n1, n2 = normal[k, 0], normal[k, 1], normal[k, 2]
        for side in range(2):
            m = mask_b[k] if side == 0 else mask_a[k]
            if m < 0:
                continue
            p = point_b[k] if side == 0 else point_a[k]
            sign = 1.0 if side == 0 else -1.0
            # n . (v - p x w) = n . v + (p x n) . w
            c0 = p[1] * n2 - p[2] * n1
            c1 = p[2] * n0 - p[0] * n2
            c2 = p[0] * n1 - p[1] * n0
            for j in range(nv):
                if masks[m, j] == 0.0:
                    continue
                rows_out[k, j] += sign * (n0 * joint_jacobians[0, j] + n1 * joint_jacobians[1, j]
                                          + n2 * joint_jacobians[2, j] + c0 * joint_jacobians[3, j]
                                          + c1 * joint_jacobians[4, j] + c2 * joint_jacobians[5, j])


def warm_up() -> None:
    """Compile (or load from numba's cache) the kernels with the argument types the IK passes,
    so the first control tick does not pay for it (~0.3 s cached; compiling takes ~10 s)."""
    nv = 35
    rows = np.empty((6, nv))
    jacobians = np.zeros((6, nv), order="F")  # pinocchio's data.J is column-major
    frame_rows(jacobians, np.eye(4)[None].copy(), np.array([[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0]]),
               np.ones((1, nv)), np.array([True]), np.zeros(1, dtype=np.int64), rows, np.empty(6))
    q = np.zeros(9)
    q[6] = 1.0
    parents = np.array([0, 0, 1], dtype=np.int64)
    rot, pos = np.zeros((3, 3, 3)), np.zeros((3, 3))
    joint_placements(q, parents, np.tile(np.eye(3), (3, 1, 1)), np.zeros((3, 3)), np.array([-1, -1, 0]), rot, pos)
    one = np.zeros(1, dtype=np.int64)
    capsule_gaps(rot, pos, np.array([1, 2], dtype=np.int64), np.zeros((2, 2, 3)), np.ones(2), one, one + 1,
                 np.array([-1], dtype=np.int64), np.zeros((1, 4)), np.array([0, 1], dtype=np.int64),
                 np.zeros((2, 2, 3)), np.zeros(1))
    witness_rows(jacobians, np.ones((3, nv)), np.zeros((1, 3)), one, np.zeros((1, 3)), one - 1,
                 np.zeros((1, 3)), np.zeros((1, nv)))

