"""The control loop's fingers (its "hands" stage): the reference's hands, through the hands' safety layer.

Per Dex3-1 hand, every hands tick:
- the plan asks for a grasp (KinematicReference.grasp_nm[hand] > 0): a ForceLimitedGrasp
  (trackers/grasp.py) with that torque limit closes the hand on what is in it, each finger stopping
  where it feels the object; a new grasp (or a new limit) starts closing from where the fingers are;
- else the fingers go to the plan's finger angles (KinematicReference.hand_q_rad, the generator's
  fingers on a G1 with hands), or open, under the gentle law the hand holds its open pose with
  (FOLLOW_KP, FOLLOW_KD);
- the body's safety layer has damped the robot (a trip, a fall, an e-stop): the fingers are damped
  too, latched (GuardedHands.trip), as on the robot.
Every command goes through GuardedHands (safety/hands.py: limits, speed ramp, gain caps, NaN
refused and damped), the same layer `g1 hands grasp` drives the real hands through.
"""

from __future__ import annotations

import numpy as np

from g1_control.interfaces import Hands
from g1_control.robot import dex3
from g1_control.safety.hands import GuardedHands
from g1_control.trackers.grasp import ForceLimitedGrasp
from g1_control.types import FingerCommand, KinematicReference

FOLLOW_KP = 2.0
"""Finger stiffness (N m/rad) following the plan's angles or holding open: the simulated hand's own
open-pose law (robot/description.py FINGER_STIFFNESS_NM_PER_RAD)."""
FOLLOW_KD = 0.05


def _finger_slots(side: dex3.Side) -> np.ndarray:
    """Indices into hand_q_rad (dex3.REFERENCE_FINGER_JOINTS order) of the hand's motors, in motor order."""
    return np.array([dex3.REFERENCE_FINGER_JOINTS.index(name) for name in dex3.joint_names(side)])


class HandsStage(Hands):
    def __init__(self, hands: GuardedHands):
        self.hands = hands
        self.sides: tuple[dex3.Side, ...] = tuple(hands.link.sides)
        self._slots = {side: _finger_slots(side) for side in self.sides}
        self._index = {side: dex3.SIDES.index(side) for side in self.sides}
        self._open = {side: dex3.hand_limits(side).open_rad for side in self.sides}
        self.grasps: dict[str, ForceLimitedGrasp | None] = {side: None for side in self.sides}
        """The grasp each hand is making (None: not grasping)."""

    @property
    def tripped(self) -> str | None:
        return self.hands.tripped

    def reset(self) -> None:
        self.hands.reset_trip()
        self.grasps = {side: None for side in self.sides}

    def update(self, ref: KinematicReference | None, now_s: float, body_faulted: bool) -> None:
        if body_faulted:
            if self.hands.tripped is None:
                self.hands.trip("the body's safety layer damped the robot; the fingers were damped with it")
            return
        for side in self.sides:
            limit = float(ref.grasp_nm[self._index[side]]) if ref is not None else 0.0
            if limit > 0.0:
                grasp = self.grasps[side]
                if grasp is None or grasp.torque_limit_nm != limit:
                    try:
                        grasp = self.grasps[side] = ForceLimitedGrasp(side, torque_limit_nm=limit)
                    except ValueError as exc:  # a limit past the motors' effort: damp, never squeeze
                        self.hands.trip(f"{side} hand: the plan's grasp is refused: {exc}; the fingers were damped")
                        return
                state = self.hands.link.read(side)
                if state is None:  # no state yet: the safety layer refuses and damps (write below)
                    command = FingerCommand.damping(self.hands.link.damping_kd)
                else:
                    command = grasp.act(state, now_s)
            else:
                self.grasps[side] = None
                if ref is not None and ref.hand_q_rad is not None:
                    q = np.asarray(ref.hand_q_rad, dtype=float)[self._slots[side]]
                else:
                    q = self._open[side]
                command = FingerCommand(q_rad=q.copy(), kp=np.full(dex3.NUM_MOTORS, FOLLOW_KP),
                                        kd=np.full(dex3.NUM_MOTORS, FOLLOW_KD))
            self.hands.write(side, command)


__all__ = ["FOLLOW_KD", "FOLLOW_KP", "HandsStage"]
