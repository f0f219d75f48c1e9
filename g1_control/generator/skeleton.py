"""The G1 variants the generator models, as skeletons over one shared set of joint slots.

Slots: the 29 body joints (g1.JOINT_NAMES order) then the 14 Dex3-1 finger joints (FINGER_JOINTS).
A skeleton says which slots exist on a variant; the others are absent (value 0, never given,
never predicted). Measured on example-robot-data's two URDFs: every one of the 29 body joint
placements is identical with and without the Dex3 hands, and the 23-DoF G1 (mode_machine 4) is
the 29-DoF tree with waist roll/pitch and wrist pitch/yaw gone (their links rigidly attached at
angle 0). So one forward kinematics serves the body of all three; the skeletons differ in which
joints exist and, for the hands, in the finger chains.

The model sees a skeleton through `descriptor()`: per slot (present, joint placement
translation in its parent (m), rotation axis one-hot), read from the URDF, so a skeleton is an
input, not a label (UniMoGen's point: one network, skeleton given).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from g1_control.errors import G1ControlError
from g1_control.robot import dex3, g1

SIDES = ("left", "right")
FINGER_JOINTS: tuple[str, ...] = dex3.REFERENCE_FINGER_JOINTS
"""The 14 finger slots (robot/dex3.py keeps the order, for the loop's hands stage to read them by name)."""
NUM_BODY = g1.NUM_JOINTS
NUM_FINGERS = len(FINGER_JOINTS)
NUM_SLOTS = NUM_BODY + NUM_FINGERS
SLOT_NAMES: tuple[str, ...] = g1.JOINT_NAMES + FINGER_JOINTS
HAND_URDF_RELATIVE = "robots/g1_description/urdf/g1_29dof_with_hand_rev_1_0.urdf"

SKELETONS = ("g1_29dof", "g1_23dof", "g1_29dof_with_hand")
"""Variants with a library and a model. (g1_29dof_locked_waist exists as a robot but has no data.)"""
DESCRIPTOR_WIDTH = 7


class SkeletonError(G1ControlError):
    """Unknown variant, or a model that does not serve the robot's variant."""


@dataclass(frozen=True)
class Skeleton:
    name: str
    present: np.ndarray
    """(NUM_SLOTS,) bool."""
    q_min: np.ndarray
    q_max: np.ndarray
    """(NUM_SLOTS,) joint limits; absent slots (0, 0)."""

    @property
    def has_fingers(self) -> bool:
        return bool(self.present[NUM_BODY:].any())

    def descriptor(self) -> np.ndarray:
        """(NUM_SLOTS, DESCRIPTOR_WIDTH) float32: present, placement xyz, axis one-hot (x, y, z)."""
        return _descriptor(self.name)


def _hand_model():
    import pinocchio as pin

    from g1_control.robot import description

    return pin.buildModelFromUrdf(str(description.description_dir() / HAND_URDF_RELATIVE), pin.JointModelFreeFlyer())


@functools.cache
def finger_limits() -> tuple[np.ndarray, np.ndarray]:
    """(14,) lower and upper finger limits from the Dex3 URDF."""
    model = _hand_model()
    lo, hi = [], []
    for name in FINGER_JOINTS:
        idx = model.joints[model.getJointId(name)].idx_q
        lo.append(model.lowerPositionLimit[idx])
        hi.append(model.upperPositionLimit[idx])
    return np.array(lo), np.array(hi)


@functools.cache
def _placements() -> tuple[np.ndarray, np.ndarray]:
    """Per slot: placement translation (NUM_SLOTS, 3) and axis index (NUM_SLOTS,) from the hand URDF
    (its body joints are the 29-DoF model's)."""
    model = _hand_model()
    pos, axis = [], []
    for name in SLOT_NAMES:
        jid = model.getJointId(name)
        pos.append(model.jointPlacements[jid].translation.copy())
        axis.append("XYZ".index(model.joints[jid].shortname()[-1]))
    return np.array(pos), np.array(axis)


@functools.cache
def _descriptor(name: str) -> np.ndarray:
    sk = skeleton(name)
    pos, axis = _placements()
    out = np.zeros((NUM_SLOTS, DESCRIPTOR_WIDTH), dtype=np.float32)
    out[:, 0] = sk.present
    out[:, 1:4] = pos * sk.present[:, None]
    out[np.arange(NUM_SLOTS), 4 + axis] = sk.present
    out.setflags(write=False)
    return out


@functools.cache
def skeleton(name: str) -> Skeleton:
    if name not in SKELETONS:
        raise SkeletonError(f"unknown generator skeleton '{name}'; known: {', '.join(SKELETONS)}")
    present = np.zeros(NUM_SLOTS, dtype=bool)
    if name == "g1_23dof":
        present[list(g1.G1_23DOF.active_joints)] = True
    else:
        present[:NUM_BODY] = True
    if name == "g1_29dof_with_hand":
        present[NUM_BODY:] = True
    f_lo, f_hi = finger_limits() if name == "g1_29dof_with_hand" else (np.zeros(NUM_FINGERS), np.zeros(NUM_FINGERS))
    q_min = np.where(present, np.concatenate([g1.Q_MIN_RAD, f_lo]), 0.0)
    q_max = np.where(present, np.concatenate([g1.Q_MAX_RAD, f_hi]), 0.0)
    for a in (present, q_min, q_max):
        a.setflags(write=False)
    return Skeleton(name, present, q_min, q_max)


def skeleton_for_robot(variant: str, hands: str = "none") -> str:
    """The generator skeleton of a launch file's robot: backend.expected_variant (+ backend.hands)."""
    if hands == "dex3":
        if variant != "g1_29dof":
            raise SkeletonError(f"Dex3 hands are modelled on the 29-DoF G1 only; the launch file's robot is {variant}")
        return "g1_29dof_with_hand"
    if variant not in SKELETONS:
        raise SkeletonError(f"the generator has no model for robot variant '{variant}'; it serves "
                            f"{', '.join(s for s in SKELETONS if s != 'g1_29dof_with_hand')} (and g1_29dof with "
                            "backend.hands: dex3)")
    return variant


def finger_mirror() -> tuple[np.ndarray, np.ndarray]:
    """Permutation and signs that mirror the 14 finger slots left <-> right (y -> -y: rotations about
    y keep their sign, about z flip)."""
    perm = np.array([FINGER_JOINTS.index(n.replace("left_", "RIGHT_").replace("right_", "left_").replace("RIGHT_", "right_"))
                     for n in FINGER_JOINTS])
    _, axis = _placements()
    sign = np.where(axis[NUM_BODY:] == 1, 1.0, -1.0)
    return perm, sign
