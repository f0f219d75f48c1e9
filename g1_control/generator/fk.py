"""Batched forward kinematics of the G1's 30 library bodies (pelvis + each joint's child link),
in numpy and torch, from the pinocchio model's joint tree.

The per-frame pinocchio loop of motion.kinematics costs ~30 us a frame in Python; evaluation
needs FK of thousands of generated frames per method and training needs it differentiable, so
this walks the tree once per batch: 29 small batched matrix products. Checked against
pinocchio to 1e-9 in tests.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from g1_control.robot import description, g1


@dataclass(frozen=True)
class KinematicTree:
    parent: tuple[int, ...]
    """Per joint (g1 order): index of the parent body in the 30-body list (0 = pelvis)."""
    offset_pos: np.ndarray
    """(29, 3) joint placement translation in the parent body frame."""
    offset_rot: np.ndarray
    """(29, 3, 3) joint placement rotation in the parent body frame."""
    axis: tuple[int, ...]
    """Per joint: rotation axis 0 (x), 1 (y) or 2 (z)."""


@functools.cache
def kinematic_tree() -> KinematicTree:
    model = description.pinocchio_model()
    joint_ids = [model.getJointId(n) for n in g1.JOINT_NAMES]
    body_of_joint = {1: 0} | {jid: k + 1 for k, jid in enumerate(joint_ids)}
    parent, pos, rot, axis = [], [], [], []
    for jid in joint_ids:
        parent.append(body_of_joint[model.parents[jid]])
        placement = model.jointPlacements[jid]
        pos.append(placement.translation.copy())
        rot.append(placement.rotation.copy())
        kind = model.joints[jid].shortname()
        if kind not in ("JointModelRX", "JointModelRY", "JointModelRZ"):
            raise NotImplementedError(f"joint {model.names[jid]} is {kind}; fk.py handles axis-aligned revolute joints")
        axis.append("XYZ".index(kind[-1]))
    return KinematicTree(tuple(parent), np.array(pos), np.array(rot), tuple(axis))


@functools.cache
def head_offset() -> np.ndarray:
    """The head point in the torso link frame: the head link's placement plus its centre of mass,
    read from the URDF (the head is rigid on the torso)."""
    import xml.etree.ElementTree as ET

    root = ET.parse(description.urdf_path()).getroot()
    joint = next(j for j in root.iter("joint") if j.get("name") == "head_joint")
    link = next(lk for lk in root.iter("link") if lk.get("name") == "head_link")
    origin, inertial = joint.find("origin"), link.find("inertial/origin")
    if origin is None or inertial is None:
        raise ValueError(f"{description.urdf_path()}: head_joint has no origin or head_link no inertial origin")
    placement = np.array([float(v) for v in origin.get("xyz", "0 0 0").split()])
    com = np.array([float(v) for v in inertial.get("xyz", "0 0 0").split()])
    out = placement + com  # the head joint's rpy is zero in Unitree's description
    out.setflags(write=False)
    return out


def _axis_rotation_np(axis: int, angle: np.ndarray) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    out = np.zeros(angle.shape + (3, 3))
    i, j = [(1, 2), (2, 0), (0, 1)][axis]
    out[..., axis, axis] = 1.0
    out[..., i, i] = c
    out[..., j, j] = c
    out[..., i, j] = -s
    out[..., j, i] = s
    return out


def fk_numpy(root_pos: np.ndarray, root_rot: np.ndarray, joints: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(..., 3), (..., 3, 3), (..., 29) -> body positions (..., 30, 3) and rotations (..., 30, 3, 3)."""
    tree = kinematic_tree()
    pos = [root_pos]
    rot = [root_rot]
    for k in range(g1.NUM_JOINTS):
        p, r = pos[tree.parent[k]], rot[tree.parent[k]]
        pos.append(p + np.einsum("...ij,j->...i", r, tree.offset_pos[k]))
        rot.append(r @ tree.offset_rot[k] @ _axis_rotation_np(tree.axis[k], joints[..., k]))
    return np.stack(pos, axis=-2), np.stack(rot, axis=-3)


def fk_torch(root_pos, root_rot, joints, num_joints: int | None = None):
    """Torch version of fk_numpy (differentiable). num_joints: only the bodies of the first
    num_joints joints (and the pelvis); the tree is in topological order, so a prefix of it is a
    whole subtree (the first 12 joints are the two legs, down to the ankle roll links)."""
    import torch

    tree = kinematic_tree()
    off_p = torch.as_tensor(tree.offset_pos, dtype=root_pos.dtype)
    off_r = torch.as_tensor(tree.offset_rot, dtype=root_pos.dtype)
    pos, rot = [root_pos], [root_rot]
    for k in range(g1.NUM_JOINTS if num_joints is None else num_joints):
        p, r = pos[tree.parent[k]], rot[tree.parent[k]]
        pos.append(p + (r @ off_p[k].unsqueeze(-1)).squeeze(-1))
        q = joints[..., k]
        c, s = torch.cos(q), torch.sin(q)
        one, zero = torch.ones_like(q), torch.zeros_like(q)
        a = tree.axis[k]
        if a == 0:
            m = torch.stack([one, zero, zero, zero, c, -s, zero, s, c], -1)
        elif a == 1:
            m = torch.stack([c, zero, s, zero, one, zero, -s, zero, c], -1)
        else:
            m = torch.stack([c, -s, zero, s, c, zero, zero, zero, one], -1)
        rot.append(r @ off_r[k] @ m.reshape(q.shape + (3, 3)))
    return torch.stack(pos, dim=-2), torch.stack(rot, dim=-3)


@functools.cache
def _effector_body_indices() -> tuple[tuple[int, ...], int]:
    from g1_control.motion.kinematics import default_body_names

    names = default_body_names()
    ends = (*g1.HAND_BODIES, *g1.FOOT_BODIES)
    return tuple(names.index(b) for b in ends), names.index(g1.TORSO_BODY)


def effectors_torch(pos, rot):
    """Effector positions (..., 5, 3) (features.EFFECTOR_BODIES order) from fk_torch's bodies."""
    import torch

    ends, torso = _effector_body_indices()
    off = torch.tensor(np.array(head_offset()), dtype=pos.dtype)
    head = pos[..., torso, :] + (rot[..., torso, :, :] @ off.unsqueeze(-1)).squeeze(-1)
    return torch.cat([pos[..., list(ends), :], head.unsqueeze(-2)], dim=-2)
