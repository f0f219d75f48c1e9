"""Foot locking: a generated gap's stance feet held where they stand.

A learned in-betweener's feet slide while they are on the ground (the backbone's stance-foot
speed at gap 30 is about twice the ground truth's). Foot locking is the classical clean-up of a
generated motion (Kovar, Schreiner and Gleicher 2002, "Footskate cleanup for motion capture
editing"): find the frames where a foot is on the ground, give every such run of frames one
anchor, and move the leg by inverse kinematics so the foot stays on its anchor. Here:

1. Contact: a foot's ankle-roll link origin within `band_m` of its standing height
   (`STANCE_ANKLE_Z_M`), on the gap's frames and on the two fixed frames around it (the last
   context frame and the target keyframe).
2. Anchors: a run of contact frames that starts at the context frame keeps the context's foot
   position (the robot's foot is there); one that ends at the target keeps the target's (when the
   target gives the root and the leg), or the gap's last frame's; a run touching both glides from
   one to the other; any other run is held at its mean. Only the horizontal position is held.
3. The correction (anchor minus generated position) is spread over the swing frames between two
   runs linearly, so a swing leaves from its anchor and arrives at the next, and is 0 at the
   fixed frames.
4. Each leg (hip pitch .. ankle roll, 6 joints) takes one damped Gauss-Newton step (`iterations`)
   on the foot's position and orientation (the generated orientation kept) with the root fixed,
   within the joint limits; the foot effectors move with it to first order. A correction beyond `max_shift_m` is scaled down to it (a leg is not asked for
   more than a short reach).

Everything is vectorised over the batch and the frames; it runs on numpy and the generator's own
kinematic tree (generator/fk.py), no pinocchio.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from g1_control.generator import features as F
from g1_control.generator.evaluation import CONTACT_BAND_M, STANCE_ANKLE_Z_M
from g1_control.generator.fk import kinematic_tree
from g1_control.robot import g1

_LEG_BODY = (6, 12)
"""The ankle-roll link's body index (fk's 30-body order) per leg; joints 0-5 left, 6-11 right."""


@dataclass(frozen=True)
class FootLockConfig:
    band_m: float = CONTACT_BAND_M
    max_shift_m: float = 0.15
    iterations: int = 1
    floor_tolerance_m: float = 0.005
    damping: float = 1e-4

    def __post_init__(self) -> None:
        for name in ("band_m", "max_shift_m", "damping", "floor_tolerance_m"):
            v = getattr(self, name)
            if not np.isfinite(v) or v < 0:
                raise ValueError(f"FootLockConfig.{name} must be finite and >= 0, got {v}")
        if self.iterations < 1:
            raise ValueError(f"FootLockConfig.iterations must be >= 1, got {self.iterations}")


@functools.cache
def _leg_tree() -> tuple:
    """The legs' part of the kinematic tree, arranged for _leg_fk: per joint its parent, placement,
    whether the placement rotates, and the index arrays that write all 12 joint rotations at once."""
    tree = kinematic_tree()
    axes = np.array(tree.axis[:12])
    planes = np.array([[(1, 2), (2, 0), (0, 1)][a] for a in axes])
    k = np.arange(12)
    unrotated = tuple(bool(np.allclose(r, np.eye(3))) for r in tree.offset_rot[:12])
    return tree.parent[:12], tree.offset_pos[:12], tree.offset_rot[:12], unrotated, (k, axes, planes[:, 0], planes[:, 1])


def _leg_fk(root_pos: np.ndarray, root_rot: np.ndarray, legs: np.ndarray):
    """(..., 3), (..., 3, 3), (..., 12) -> positions (..., 13, 3), rotations (..., 13, 3, 3) of the
    pelvis and the 12 leg bodies (the tree's first 12 joints are the two legs)."""
    parent, offset_pos, offset_rot, unrotated, (k, a, i, j) = _leg_tree()
    cos, sin = np.cos(legs), np.sin(legs)
    m = np.zeros(legs.shape + (3, 3))  # every joint's rotation about its axis
    m[..., k, a, a] = 1.0
    m[..., k, i, i] = cos
    m[..., k, j, j] = cos
    m[..., k, i, j] = -sin
    m[..., k, j, i] = sin
    pos, rot = [root_pos], [root_rot]
    for n in range(12):
        p, r = pos[parent[n]], rot[parent[n]]
        pos.append(p + r @ offset_pos[n])
        rot.append((r if unrotated[n] else r @ offset_rot[n]) @ m[..., n, :, :])
    return np.stack(pos, axis=-2), np.stack(rot, axis=-3)


def feet_of(frames: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Ankle-roll link positions (..., 2, 3) and rotations (..., 2, 3, 3) of feature frames."""
    pos, rot = _leg_fk(frames[..., F.ROOT_POS], F.rot6d_to_matrix(frames[..., F.ROOT_ROT]), frames[..., 9:21])
    return pos[..., _LEG_BODY, :], rot[..., _LEG_BODY, :, :]


def _runs(contact: np.ndarray) -> list[tuple[int, int]]:
    """Inclusive index ranges of the True runs of a 1-D bool array."""
    out, start = [], None
    for i, c in enumerate(contact):
        if c and start is None:
            start = i
        if not c and start is not None:
            out.append((start, i - 1))
            start = None
    if start is not None:
        out.append((start, len(contact) - 1))
    return out


def _offsets(xy: np.ndarray, contact: np.ndarray) -> np.ndarray:
    """One foot of one window over the extended sequence (context frame, gap, end frame):
    xy (T + 2, 2), contact (T + 2,) -> the horizontal correction per frame (T + 2, 2), 0 at both
    ends."""
    n = len(contact)
    off = np.zeros((n, 2))
    known = np.zeros(n, dtype=bool)
    known[0] = known[-1] = True
    for a, b in _runs(contact):
        if a == 0 and b == n - 1:
            w = np.linspace(0.0, 1.0, n)[:, None]
            anchor = (1 - w) * xy[0] + w * xy[-1]
            off[:] = anchor - xy
        else:
            anchor = xy[0] if a == 0 else xy[-1] if b == n - 1 else xy[a:b + 1].mean(axis=0)
            off[a:b + 1] = anchor - xy[a:b + 1]
        known[a:b + 1] = True
    off[0] = off[-1] = 0.0
    idx = np.flatnonzero(known)
    for d in range(2):
        off[:, d] = np.interp(np.arange(n), idx, off[idx, d])
    return off


def _rot_error(target: np.ndarray, rot: np.ndarray) -> np.ndarray:
    """Small-angle rotation vector taking rot to target (world frame), (..., 3)."""
    e = target @ np.swapaxes(rot, -1, -2)
    return 0.5 * np.stack([e[..., 2, 1] - e[..., 1, 2], e[..., 0, 2] - e[..., 2, 0], e[..., 1, 0] - e[..., 0, 1]], -1)


def lock_feet(frames: np.ndarray, context_last: np.ndarray, end: np.ndarray, end_given: np.ndarray | None = None,
              config: FootLockConfig | None = None) -> np.ndarray:
    """Generated gap frames (B, T, D) with their stance feet held (a new array; joints, effectors
    changed, the root kept). context_last (B, D): the frame before the gap; end (B, D): the target
    keyframe; end_given (B,) bool: whether the target gives the root and the legs (else the gap's
    last frame stands in for it)."""
    cfg = config or FootLockConfig()
    b, t, _ = frames.shape
    if b == 0 or t == 0:
        return frames.copy()
    if end_given is None:
        end_given = np.ones(b, dtype=bool)
    last = np.where(end_given[:, None], end, frames[:, -1])
    seq = np.concatenate([context_last[:, None], frames, last[:, None]], axis=1)  # (B, T + 2, D)
    seq_root_rot = F.rot6d_to_matrix(seq[..., F.ROOT_ROT])
    seq_pos, seq_rot = _leg_fk(seq[..., F.ROOT_POS], seq_root_rot, seq[..., 9:21])
    feet, feet_rot = seq_pos[..., _LEG_BODY, :], seq_rot[..., _LEG_BODY, :, :]
    contact = feet[..., 2] < STANCE_ANKLE_Z_M + cfg.band_m  # (B, T + 2, 2)
    off = np.zeros(feet.shape[:-1] + (2,))
    for i in range(b):
        for s in range(2):
            if contact[i, :, s].any():
                off[i, :, s] = _offsets(feet[i, :, s, :2], contact[i, :, s])
    norm = np.linalg.norm(off, axis=-1, keepdims=True)
    off *= np.minimum(1.0, cfg.max_shift_m / np.maximum(norm, 1e-12))
    off = off[:, 1:-1]  # the gap's frames
    held = contact[:, 1:-1]
    sunk = held & (feet[:, 1:-1, :, 2] < STANCE_ANKLE_Z_M - cfg.floor_tolerance_m)
    if not np.any(np.abs(off) > 1e-6) and not sunk.any():
        return frames.copy()
    goal = feet[:, 1:-1].copy()
    goal[..., :2] += off
    # a stance foot generated through the floor is lifted onto it
    goal[..., 2] = np.where(held, np.maximum(goal[..., 2], STANCE_ANKLE_Z_M - cfg.floor_tolerance_m), goal[..., 2])
    goal_rot = feet_rot[:, 1:-1]
    out = frames.copy()
    root_pos = out[..., F.ROOT_POS]
    root_rot = seq_root_rot[:, 1:-1]
    legs = out[..., 9:21].copy()
    lo, hi = g1.Q_MIN_RAD[:12], g1.Q_MAX_RAD[:12]
    unit_axis = np.eye(3)[list(kinematic_tree().axis[:12])]  # (12, 3): each leg joint's axis, its own frame
    body_of = np.arange(1, 13)
    foot_of = np.repeat(np.array(_LEG_BODY), 6)  # each leg joint's foot
    damp = cfg.damping * np.eye(6)
    pos, rot = seq_pos[:, 1:-1], seq_rot[:, 1:-1]  # the gap's legs as generated
    moved = np.zeros(goal.shape)  # (B, T, 2, 3): how far each foot moved
    for it in range(cfg.iterations):
        if it:
            pos, rot = _leg_fk(root_pos, root_rot, legs)
        feet_pos, feet_rot = pos[..., _LEG_BODY, :], rot[..., _LEG_BODY, :, :]
        e = np.concatenate([goal - feet_pos, _rot_error(goal_rot, feet_rot)], -1)  # (B, T, 2, 6)
        axes = np.einsum("...kij,kj->...ki", rot[..., body_of, :, :], unit_axis)  # (B, T, 12, 3): joint axes, world
        lever = pos[..., foot_of, :] - pos[..., body_of, :]
        cross = np.stack([axes[..., 1] * lever[..., 2] - axes[..., 2] * lever[..., 1],
                          axes[..., 2] * lever[..., 0] - axes[..., 0] * lever[..., 2],
                          axes[..., 0] * lever[..., 1] - axes[..., 1] * lever[..., 0]], -1)
        cols = np.concatenate([cross, axes], -1).reshape(cross.shape[:-2] + (2, 6, 6))  # (B, T, leg, joint, 6)
        jac = np.swapaxes(cols, -1, -2)  # (B, T, leg, 6 rows, 6 joints)
        jt = cols
        step = np.linalg.solve(jt @ jac + damp, jt @ e[..., None])[..., 0]  # (B, T, 2, 6)
        new = np.clip(legs + step.reshape(step.shape[:-2] + (12,)), lo, hi)
        moved += (jac @ (new - legs).reshape(step.shape)[..., None])[..., :3, 0]  # to first order
        legs = new
    out[..., 9:21] = legs
    # the foot effectors move with the feet, to first order (the runtime keeps the effectors as the
    # in-betweener made them, runtime.py; an FK here would cost as much as the solve)
    for s, name in enumerate(g1.FOOT_BODIES):
        out[..., F.effector_slice(name)] += moved[..., s, :]
    return out


def end_given(target_mask: np.ndarray) -> np.ndarray:
    """(B, D) target masks -> (B,) whether each target gives the root and both legs (the feet)."""
    return np.asarray(target_mask[:, F.ROOT].all(axis=1) & target_mask[:, 9:21].all(axis=1))


class FootLockedInbetweener:
    """Any Inbetweener with its gap's stance feet held (lock_feet): the rows "backbone+foot lock"
    of `g1 bench generator`. The runtime (runtime.py) locks its plans itself, after the feedback."""

    def __init__(self, inner, config: FootLockConfig | None = None, name: str | None = None):
        self.inner = inner
        self.config = config or FootLockConfig()
        self.name = name or f"{inner.name}+foot lock"

    def set_goals(self, goal, mask) -> None:
        self.inner.set_goals(goal, mask)

    def infill(self, context, target, target_mask, gap, style):
        frames = self.inner.infill(context, target, target_mask, gap, style)
        return lock_feet(frames, context[:, -1], target, end_given(target_mask), self.config)
