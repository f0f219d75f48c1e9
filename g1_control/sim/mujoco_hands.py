"""The simulated G1's Dex3-1 hands as a hand link: what safety/hands.py's GuardedHands and
trackers/grasp.py's ForceLimitedGrasp drive on the robot over DDS (hardware/hand_link.py), here on
MuJoCo's fingers (robot/description.py: a motor per finger joint under the hand's motor law), so a
grasp closes real finger bodies on real objects and is judged by their contacts.

    hands = GuardedHands(MujocoHandLink(backend), clock=lambda: backend.time_s)
    hands.write("right", ForceLimitedGrasp("right", 0.5).act(hands.link.read("right"), backend.time_s))

Each read is a fresh sample of the physics, stamped with the simulated time: a simulated hand
neither drops nor freezes its state, so the safety layer's stale and frozen checks never fire here
(they guard a transport); its limits, speed ramp, gain caps and NaN refusal act as on the robot.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from g1_control.errors import RobotDescriptionError
from g1_control.robot import dex3
from g1_control.types import FingerCommand, FingerState

if TYPE_CHECKING:
    from g1_control.sim.mujoco_backend import MujocoBackend


class MujocoHandLink:
    """safety/hands.py's HandLink over a MujocoBackend built with Dex3 hands (MujocoConfig.hands 'dex3')."""

    def __init__(self, backend: MujocoBackend, damping_kd: float = dex3.DAMPING_KD):
        if not backend.hand_sides:
            raise RobotDescriptionError("this simulated G1 has no Dex3 hands (backend.hands: dex3 builds them)")
        if not damping_kd > 0:
            raise ValueError(f"damping_kd must be positive (damping needs kd > 0); got {damping_kd}")
        self.backend = backend
        self.sides: tuple[dex3.Side, ...] = tuple(s for s in dex3.SIDES if s in backend.hand_sides)
        self.damping_kd = damping_kd

    def write(self, side: dex3.Side, command: FingerCommand) -> None:
        self.backend.write_fingers(side, command)

    def read(self, side: dex3.Side) -> FingerState:
        return self.backend.read_fingers(side)

    def damp(self, sides: tuple[dex3.Side, ...] | None = None) -> None:
        for side in sides or self.sides:
            self.backend.write_fingers(side, FingerCommand.damping(self.damping_kd))

    def last_change_s(self, side: dex3.Side) -> float:
        """Every sample is the physics' own (see the module docstring): the newest one's time."""
        dex3.check_side(side)
        return self.backend.time_s


__all__ = ["MujocoHandLink"]
