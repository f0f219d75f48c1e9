"""The small interfaces every stage of the loop implements (see DESIGN.md).

operator -> InputDevice.poll() -> Command
         -> Generator.update(Command, RobotState) -> KinematicReference
         -> Retargeter.solve(KinematicReference, q_prev) -> JointReference
         -> Tracker.act(JointReference, RobotState) -> MotorCommand
         -> safety filter -> Backend.write_command(MotorCommand)
"""

from __future__ import annotations

from abc import ABC, abstractmethod

import numpy as np

from g1_control.types import Command, JointReference, KinematicReference, MotorCommand, RobotState


class Backend(ABC):
    """A robot: simulated or real. `close()` must leave it damped."""

    #: Lockstep backends advance only in step(); wall-clock ones run on their own.
    lockstep: bool = True

    @abstractmethod
    def reset(self) -> RobotState: ...

    @abstractmethod
    def read_state(self) -> RobotState: ...

    @abstractmethod
    def write_command(self, command: MotorCommand) -> None: ...

    def step(self, dt_s: float) -> None:
        """Advance `dt_s` seconds (lockstep only; a no-op on wall-clock backends)."""

    @abstractmethod
    def close(self) -> None: ...

    def __enter__(self):
        return self

    def __exit__(self, *exc) -> None:
        self.close()


class InputDevice(ABC):
    @abstractmethod
    def poll(self) -> Command: ...

    def close(self) -> None:
        """Release the device."""


class Generator(ABC):
    @abstractmethod
    def update(self, command: Command, state: RobotState) -> KinematicReference: ...

    def reset(self, state: RobotState) -> None:
        """Start over from `state`."""


class Retargeter(ABC):
    @abstractmethod
    def solve(self, reference: KinematicReference, q_prev: np.ndarray) -> JointReference: ...


class Tracker(ABC):
    @abstractmethod
    def act(self, reference: JointReference, state: RobotState) -> MotorCommand: ...

    def reset(self, state: RobotState) -> None:
        """Clear internal memory (action history, phase)."""
