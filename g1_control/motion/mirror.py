"""Left/right mirroring of G1 clips across the robot's sagittal plane (world x-z plane).

G1 sign conventions (Unitree's description): pitch joints turn about y and keep their sign when
mirrored; roll (x) and yaw (z) joints flip sign, and left/right joints swap. The left/right
limits are mirror images (e.g. hip roll left [-0.52, 2.97], right [-2.97, 0.52]), so a mirrored
clip stays within limits. Positions reflect y -> -y; orientations reflect as
(w, x, y, z) -> (w, -x, y, -z); angular velocities (pseudovectors) as (x, y, z) -> (-x, y, -z).
Mirroring twice gives back the clip exactly (only swaps and sign flips).
"""

from __future__ import annotations

import numpy as np

from g1_control.motion.clip import MotionClip
from g1_control.motion.exceptions import UnknownJointError

_FLIP_KINDS = ("_roll_joint", "_yaw_joint")


def _swap_side(name: str) -> str:
    if name.startswith("left_"):
        return "right_" + name[5:]
    if name.startswith("right_"):
        return "left_" + name[6:]
    return name


def _permutation(names: tuple[str, ...], what: str) -> np.ndarray:
    index = {n: i for i, n in enumerate(names)}
    try:
        return np.array([index[_swap_side(n)] for n in names])
    except KeyError as exc:
        raise UnknownJointError(f"cannot mirror: {what} '{exc.args[0]}' has no counterpart on the other side") from None


def joint_mirror_map(joint_names: tuple[str, ...]) -> tuple[np.ndarray, np.ndarray]:
    """(permutation, sign) with mirrored_q = sign * q[:, permutation]."""
    perm = _permutation(joint_names, "joint")
    # The joint kind (roll/yaw/pitch) is the same on both sides, so the sign is per target joint.
    sign = np.array([-1.0 if n.endswith(_FLIP_KINDS) else 1.0 for n in joint_names])
    return perm, sign


_POS = np.array([1.0, -1.0, 1.0])
_QUAT = np.array([1.0, -1.0, 1.0, -1.0])
_PSEUDO = np.array([-1.0, 1.0, -1.0])


def mirror(clip: MotionClip) -> MotionClip:
    """The clip performed with the other side of the body."""
    jperm, jsign = joint_mirror_map(clip.joint_names)
    bperm = _permutation(clip.body_names, "body")
    return MotionClip(
        fps=clip.fps, joint_names=clip.joint_names, body_names=clip.body_names,
        root_pos_w_m=clip.root_pos_w_m * _POS,
        root_quat_wxyz=clip.root_quat_wxyz * _QUAT,
        joint_pos_rad=clip.joint_pos_rad[:, jperm] * jsign,
        joint_vel_radps=clip.joint_vel_radps[:, jperm] * jsign,
        body_pos_w_m=clip.body_pos_w_m[:, bperm] * _POS,
        body_quat_wxyz=clip.body_quat_wxyz[:, bperm] * _QUAT,
        body_lin_vel_w_mps=clip.body_lin_vel_w_mps[:, bperm] * _POS,
        body_ang_vel_w_radps=clip.body_ang_vel_w_radps[:, bperm] * _PSEUDO,
        contacts=clip.contacts[:, ::-1].copy(),
        source=clip.source, style=clip.style, tags=tuple(clip.tags),
        object=None if clip.object is None else clip.object.mirrored(),
        scene=tuple(shape.mirrored() for shape in clip.scene),
    )
