"""Unitree G1 facts: the one place every other module reads them from.

Joint order, limits and motor families follow Unitree's G1 description (identical in
example-robot-data's URDF, MuJoCo Menagerie's g1.xml and holosoma's policy metadata). Position,
velocity and effort limits are the URDF's (tests/robot check them against the file); the
safety layer, the IK and the clip metrics all read them from here.
Armature (reflected rotor inertia) per motor family is the value mjlab / BeyondMimic derive
from each family's rotor inertias and planetary gear stages; the policies were trained with it.
Gains follow the same recipe as those projects: kp = armature * wn^2, kd = 2 * zeta * armature * wn
with wn = 2*pi*10 rad/s and zeta = 2, which reproduces the kp/kd stored in holosoma's ONNX files.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np

NUM_MOTOR_SLOTS = 35
"""LowCmd_/LowState_ carry 35 motor slots; the G1 uses the first 29."""

JOINT_NAMES: tuple[str, ...] = (
    "left_hip_pitch_joint",
    "left_hip_roll_joint",
    "left_hip_yaw_joint",
    "left_knee_joint",
    "left_ankle_pitch_joint",
    "left_ankle_roll_joint",
    "right_hip_pitch_joint",
    "right_hip_roll_joint",
    "right_hip_yaw_joint",
    "right_knee_joint",
    "right_ankle_pitch_joint",
    "right_ankle_roll_joint",
    "waist_yaw_joint",
    "waist_roll_joint",
    "waist_pitch_joint",
    "left_shoulder_pitch_joint",
    "left_shoulder_roll_joint",
    "left_shoulder_yaw_joint",
    "left_elbow_joint",
    "left_wrist_roll_joint",
    "left_wrist_pitch_joint",
    "left_wrist_yaw_joint",
    "right_shoulder_pitch_joint",
    "right_shoulder_roll_joint",
    "right_shoulder_yaw_joint",
    "right_elbow_joint",
    "right_wrist_roll_joint",
    "right_wrist_pitch_joint",
    "right_wrist_yaw_joint",
)
NUM_JOINTS = len(JOINT_NAMES)
JOINT_INDEX = {name: i for i, name in enumerate(JOINT_NAMES)}

LEG_JOINTS = tuple(range(12))
WAIST_JOINTS = (12, 13, 14)
ARM_JOINTS = tuple(range(15, 29))
UPPER_BODY_JOINTS = WAIST_JOINTS + ARM_JOINTS

# (lower, upper) in rad, Unitree's description.
_LIMITS = {
    "hip_pitch": (-2.5307, 2.8798),
    "left_hip_roll": (-0.5236, 2.9671),
    "right_hip_roll": (-2.9671, 0.5236),
    "hip_yaw": (-2.7576, 2.7576),
    "knee": (-0.087267, 2.8798),
    "ankle_pitch": (-0.87267, 0.5236),
    "ankle_roll": (-0.2618, 0.2618),
    "waist_yaw": (-2.618, 2.618),
    "waist_roll": (-0.52, 0.52),
    "waist_pitch": (-0.52, 0.52),
    "shoulder_pitch": (-3.0892, 2.6704),
    "left_shoulder_roll": (-1.5882, 2.2515),
    "right_shoulder_roll": (-2.2515, 1.5882),
    "shoulder_yaw": (-2.618, 2.618),
    "elbow": (-1.0472, 2.0944),
    "wrist_roll": (-1.972222054, 1.972222054),
    "wrist_pitch": (-1.614429558, 1.614429558),
    "wrist_yaw": (-1.614429558, 1.614429558),
}


@dataclass(frozen=True)
class MotorFamily:
    """A Unitree actuator family as the joint sees it (after the gearbox)."""

    name: str
    effort_limit_nm: float
    velocity_limit_radps: float
    armature_kgm2: float


# Armature values: mjlab's G1 constants (reflected inertia of each family's rotor and gears).
MOTOR_5020 = MotorFamily("5020", 25.0, 37.0, 0.003609725)
MOTOR_5020_X2 = MotorFamily("5020x2", 35.0, 30.0, 2 * 0.003609725)
"""Ankles and waist roll/pitch: two 5020 motors driving the joint through a parallel linkage. Limits
as Unitree's description states them (example-robot-data 6.0.0, g1_29dof_rev_1_0.urdf: effort 35,
velocity 30), the values an independent checker reads; Menagerie and holosoma's training used
50 N m / 37 rad/s. Measured (issue 12): the holosoma walking policy never needs more than 23 N m or
6 rad/s on these joints (sim_walk, sim_random), and its walking is identical under either value."""
MOTOR_7520_14 = MotorFamily("7520-14", 88.0, 32.0, 0.010177520)
MOTOR_7520_22 = MotorFamily("7520-22", 139.0, 20.0, 0.025101925)
MOTOR_4010 = MotorFamily("4010", 5.0, 22.0, 0.00425)

_FAMILY_BY_SUFFIX = {
    "hip_pitch": MOTOR_7520_14,
    "hip_roll": MOTOR_7520_22,
    "hip_yaw": MOTOR_7520_14,
    "knee": MOTOR_7520_22,
    "ankle_pitch": MOTOR_5020_X2,
    "ankle_roll": MOTOR_5020_X2,
    "waist_yaw": MOTOR_7520_14,
    "waist_roll": MOTOR_5020_X2,
    "waist_pitch": MOTOR_5020_X2,
    "shoulder_pitch": MOTOR_5020,
    "shoulder_roll": MOTOR_5020,
    "shoulder_yaw": MOTOR_5020,
    "elbow": MOTOR_5020,
    "wrist_roll": MOTOR_5020,
    "wrist_pitch": MOTOR_4010,
    "wrist_yaw": MOTOR_4010,
}


def _kind(name: str) -> str:
    """'left_hip_roll_joint' -> 'hip_roll'."""
    stem = name.removesuffix("_joint")
    for side in ("left_", "right_"):
        stem = stem.removeprefix(side)
    return stem


def _limit(name: str) -> tuple[float, float]:
    stem = name.removesuffix("_joint")
    return _LIMITS.get(stem) or _LIMITS[_kind(name)]


MOTOR_FAMILIES: tuple[MotorFamily, ...] = tuple(_FAMILY_BY_SUFFIX[_kind(n)] for n in JOINT_NAMES)
Q_MIN_RAD = np.array([_limit(n)[0] for n in JOINT_NAMES])
Q_MAX_RAD = np.array([_limit(n)[1] for n in JOINT_NAMES])
EFFORT_LIMIT_NM = np.array([f.effort_limit_nm for f in MOTOR_FAMILIES])
VELOCITY_LIMIT_RADPS = np.array([f.velocity_limit_radps for f in MOTOR_FAMILIES])
ARMATURE_KGM2 = np.array([f.armature_kgm2 for f in MOTOR_FAMILIES])

NATURAL_FREQUENCY_RADPS = 2 * math.pi * 10.0
DAMPING_RATIO = 2.0
KP_DEFAULT = ARMATURE_KGM2 * NATURAL_FREQUENCY_RADPS**2
KD_DEFAULT = 2.0 * DAMPING_RATIO * ARMATURE_KGM2 * NATURAL_FREQUENCY_RADPS

_LEG_DEFAULT = (-0.312, 0.0, 0.0, 0.669, -0.363, 0.0)
DEFAULT_Q_RAD = np.array(
    _LEG_DEFAULT
    + _LEG_DEFAULT
    + (0.0, 0.0, 0.0)
    + (0.2, 0.2, 0.0, 0.6, 0.0, 0.0, 0.0)
    + (0.2, -0.2, 0.0, 0.6, 0.0, 0.0, 0.0)
)
"""Standing pose the locomotion policies were trained around."""

DEFAULT_PELVIS_HEIGHT_M = 0.78
"""Approximate pelvis height standing in DEFAULT_Q_RAD (set at reset, then physics settles it)."""

for _arr in (Q_MIN_RAD, Q_MAX_RAD, EFFORT_LIMIT_NM, VELOCITY_LIMIT_RADPS, ARMATURE_KGM2, KP_DEFAULT,
             KD_DEFAULT, DEFAULT_Q_RAD):
    _arr.setflags(write=False)

MOTOR_MAX_TEMPERATURE_C = 120.0
"""The hottest a G1 joint motor may report before it is damaged: no motor-temperature threshold
(the runtime trip, the start check) may be set above it, or it could never fire in time. Unitree
publishes no winding or magnet rating for the G1's motors; 120 °C is the working limit of H-grade
NdFeB magnets (irreversible demagnetisation beyond it), an upper bound for any such motor. Replace
it with the vendor's figure when one is published."""

BATTERY_FULL_V = 54.6
"""The G1 battery's limited charge voltage (Unitree "G1 Battery and Charger User Manual" V1.0: 13
Li-ion cells in series, rated 46.8 V, charged to 54.6 V): a pack never reads more."""
BATTERY_EMPTY_V = 13 * 2.5
"""13 cells at 2.5 V, the discharge cut-off of Li-ion cells: a pack never delivers less (its BMS
switches off first), so a low-battery threshold below it could never fire."""

BASE_BODY = "pelvis"
TORSO_BODY = "torso_link"
FOOT_BODIES = ("left_ankle_roll_link", "right_ankle_roll_link")
HAND_BODIES = ("left_wrist_yaw_link", "right_wrist_yaw_link")
IMU_BODY = "pelvis"


@dataclass(frozen=True)
class Variant:
    """A G1 hardware variant as reported by LowState.mode_machine."""

    name: str
    mode_machine: int
    active_joints: tuple[int, ...]

    @property
    def num_dof(self) -> int:
        return len(self.active_joints)

    @property
    def active_mask(self) -> np.ndarray:
        mask = np.zeros(NUM_JOINTS, dtype=bool)
        mask[list(self.active_joints)] = True
        return mask


_DROPPED_IN_23 = {
    JOINT_INDEX[n]
    for n in ("waist_roll_joint", "waist_pitch_joint", "left_wrist_pitch_joint",
              "left_wrist_yaw_joint", "right_wrist_pitch_joint", "right_wrist_yaw_joint")
}
G1_23DOF = Variant("g1_23dof", 4, tuple(i for i in range(NUM_JOINTS) if i not in _DROPPED_IN_23))
G1_29DOF = Variant("g1_29dof", 5, tuple(range(NUM_JOINTS)))
G1_29DOF_LOCKED_WAIST = Variant(
    "g1_29dof_locked_waist", 6, tuple(i for i in range(NUM_JOINTS) if i not in (13, 14))
)
VARIANTS = {v.mode_machine: v for v in (G1_23DOF, G1_29DOF, G1_29DOF_LOCKED_WAIST)}
VariantName = Literal["g1_23dof", "g1_29dof", "g1_29dof_locked_waist"]
"""The variants' names (Variant.name), as a launch file's backend.expected_variant and a policy spec spell them."""


def variant_named(name: str) -> Variant:
    """The variant called `name` (a launch file's backend.expected_variant); raises for an unknown name."""
    for v in VARIANTS.values():
        if v.name == name:
            return v
    raise ValueError(f"unknown G1 variant '{name}'; known: {', '.join(v.name for v in VARIANTS.values())}")


def missing_joints(variant: Variant, joint_names) -> list[str]:
    """The names in `joint_names` that `variant` has no motor for (a 29-DoF policy on a 23-DoF G1)."""
    return [n for n in joint_names if n in JOINT_INDEX and JOINT_INDEX[n] not in variant.active_joints]


def variant_for_mode_machine(mode_machine: int) -> Variant:
    """The variant a robot reporting `mode_machine` is; raises for an unknown value."""
    try:
        return VARIANTS[mode_machine]
    except KeyError:
        known = ", ".join(f"{k} ({v.name})" for k, v in sorted(VARIANTS.items()))
        raise ValueError(f"unknown G1 mode_machine {mode_machine}; known: {known}") from None
