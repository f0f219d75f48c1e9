"""Unitree's Dex3-1 hands on the G1: motors, joint names and limits, and the DDS topics they speak.

Where each fact comes from:
- URDF (example-robot-data's g1_29dof_with_hand_rev_1_0.urdf, read at run time): the 7 finger
  joints per hand, their order, position limits, effort and velocity limits. Thumb 3 joints
  (thumb_0 about y, thumb_1, thumb_2), middle 2, index 2; the right hand mirrors the left.
- docs/robot_facts.md ("Dex3-1 hands"): the `unitree_hg` HandCmd_/HandState_ types and the
  topics rt/dex3/left|right/cmd (host -> hand) and rt/dex3/left|right/state (hand -> host).
- Assumed, not checked against a hand: the order of the 7 entries of motor_cmd / motor_state is
  the URDF's joint order (thumb 0-2, middle 0-1, index 0-1); the motor `mode` byte packs the motor
  id in bits 0-3, the status (1 = enabled) in bits 4-6 and a timeout flag in bit 7, as Unitree's
  Dex3 example does; the messages carry no CRC (the SDK's definitions have no crc member).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from typing import Literal

import numpy as np

from g1_control.errors import RobotDescriptionError

Side = Literal["left", "right"]
SIDES: tuple[Side, Side] = ("left", "right")
FINGERS = ("thumb_0", "thumb_1", "thumb_2", "middle_0", "middle_1", "index_0", "index_1")
"""The 7 motors of one hand, in message order (the URDF's joint order)."""
NUM_MOTORS = len(FINGERS)
REFERENCE_FINGER_JOINTS: tuple[str, ...] = tuple(f"{side}_hand_{f}_joint" for side in ("left", "right")
                                                 for f in ("thumb_0", "thumb_1", "thumb_2", "index_0", "index_1",
                                                           "middle_0", "middle_1"))
"""The 14 finger angles of a reference (KinematicReference.hand_q_rad) in the generator skeleton's slot
order (generator/skeleton.py FINGER_JOINTS is this): left then right, index before middle, unlike the
motors' order (FINGERS)."""
HAND_URDF_RELATIVE = "robots/g1_description/urdf/g1_29dof_with_hand_rev_1_0.urdf"

DAMPING_KD = 0.05
"""kd of a hand's fail-safe damping (N m s/rad, kp 0): a finger motor has 1.4-2.45 N m, so the body's
damping kd (2) would be a brake, not a damper."""
MODE_STATUS_ENABLED = 1
"""Status bits (4-6) of a motor's mode byte: 1 enables the motor (assumed from Unitree's example)."""


def joint_names(side: Side) -> tuple[str, ...]:
    check_side(side)
    return tuple(f"{side}_hand_{f}_joint" for f in FINGERS)


def check_side(side: str) -> None:
    if side not in SIDES:
        raise ValueError(f"hand side must be 'left' or 'right'; got {side!r}")


def cmd_topic(side: Side) -> str:
    check_side(side)
    return f"rt/dex3/{side}/cmd"


def state_topic(side: Side) -> str:
    check_side(side)
    return f"rt/dex3/{side}/state"


def motor_mode(index: int, enabled: bool = True, timeout: bool = False) -> int:
    """The mode byte of motor `index` (0-6): id in bits 0-3, status in bits 4-6, timeout in bit 7."""
    if not 0 <= index < NUM_MOTORS:
        raise ValueError(f"Dex3-1 motor index must be 0..{NUM_MOTORS - 1}; got {index}")
    return (index & 0x0F) | ((MODE_STATUS_ENABLED if enabled else 0) << 4) | (int(timeout) << 7)


def mode_enabled(mode: int) -> bool:
    return (int(mode) >> 4) & 0x07 == MODE_STATUS_ENABLED


@dataclass(frozen=True)
class HandLimits:
    """One hand's joint limits from the URDF, (7,) each in message order."""

    side: Side
    q_min_rad: np.ndarray
    q_max_rad: np.ndarray
    effort_nm: np.ndarray
    velocity_radps: np.ndarray

    @property
    def closing_sign(self) -> np.ndarray:
        """(7,) +1 / -1: the direction each joint turns to close the hand (toward its farther limit
        from 0, where the finger curls in); 0 for thumb_0, which swings the thumb across the palm
        instead of closing it (its range is symmetric)."""
        far = np.where(np.abs(self.q_max_rad) > np.abs(self.q_min_rad) + 1e-6, 1.0,
                       np.where(np.abs(self.q_min_rad) > np.abs(self.q_max_rad) + 1e-6, -1.0, 0.0))
        return far

    @property
    def closed_rad(self) -> np.ndarray:
        """(7,) the fully closed pose: each closing joint at its far limit, thumb_0 at 0."""
        sign = self.closing_sign
        return np.where(sign > 0, self.q_max_rad, np.where(sign < 0, self.q_min_rad, 0.0))

    @property
    def open_rad(self) -> np.ndarray:
        """(7,) the open pose: 0 clipped into the limits."""
        return np.clip(np.zeros(NUM_MOTORS), self.q_min_rad, self.q_max_rad)


@functools.cache
def hand_limits(side: Side) -> HandLimits:
    """The `<limit>` of `side`'s 7 finger joints, read from the hand URDF."""
    import xml.etree.ElementTree as ET

    from g1_control.robot import description

    check_side(side)
    path = description.description_dir() / HAND_URDF_RELATIVE
    if not path.is_file():
        raise RobotDescriptionError(f"the G1-with-hands URDF is missing at {path}; reinstall example-robot-data")
    found = {j.get("name"): j.find("limit") for j in ET.parse(path).getroot().iter("joint")}
    rows = []
    for name in joint_names(side):
        limit = found.get(name)
        if limit is None:
            raise RobotDescriptionError(f"the hand URDF {path.name} has no <limit> for {name}")
        rows.append([float(limit.get(k, "nan")) for k in ("lower", "upper", "effort", "velocity")])
    table = np.array(rows)
    if not np.all(np.isfinite(table)):
        raise RobotDescriptionError(f"the hand URDF {path.name} leaves a {side} finger limit without a number")
    cols = [table[:, i].copy() for i in range(4)]
    for c in cols:
        c.setflags(write=False)
    return HandLimits(side, *cols)
