"""The small interfaces every stage of the loop implements: the loop's whole contract with a stage.

operator -> InputDevice.observe(ExecutionFeedback); InputDevice.poll(now_s) -> Command
         -> Generator.update(Command, RobotState) -> KinematicReference
         -> Retargeter.solve(KinematicReference, q_prev) -> JointReference
         -> Tracker.observe(EstimatedState); Tracker.act(JointReference, RobotState) -> MotorCommand
         -> safety filter -> Backend.write_command(MotorCommand)

The control loop (g1_control/loop/control_loop.py) reads nothing from a stage that is not
declared here; defaults are what a stage without that capability should report.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Mapping, Sequence
from typing import Any, Protocol

import numpy as np

from g1_control.scene import Platform
from g1_control.types import (
    NO_GOALS,
    PHASE_LOCOMOTION,
    Command,
    CommandLimits,
    EstimatedState,
    ExecutionFeedback,
    JointReference,
    KinematicReference,
    MotorCommand,
    RobotState,
)


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

    def step_ticks(self, command: MotorCommand, dt_s: float, n: int) -> None:
        """`n` low-level ticks of `command` in a row: write_command(command) then step(dt_s), n times
        (lockstep). A backend that only stores the command may advance all n at once. The caller
        does not modify `command` in place once written (a new command is a new object)."""
        for _ in range(n):
            self.write_command(command)
            self.step(dt_s)

    def damp(self) -> None:
        """Put damping on the motors now, not at the next tick (signal handlers, faults)."""
        self.write_command(MotorCommand.damping())

    def ground_contacts(self) -> tuple[str, ...] | None:
        """Robot bodies other than the feet touching the ground (the static scene) now: () when
        none; None when the backend cannot tell (a robot has no such sensor). A simulator's
        ground truth, for judging falls (g1_control/safety/fall.py)."""
        return None

    @property
    def bad_crc(self) -> int:
        """States dropped so far for a bad checksum (robot links; 0 for simulators)."""
        return 0

    @property
    def peer_fault(self) -> str | None:
        """A robot link's complaint about its peers (a second publisher of the robot's state, another
        writer of its commands), or None; simulators have no peers."""
        return None

    @abstractmethod
    def close(self) -> None: ...

    def describe(self) -> str:
        """One line naming the backend, for run summaries and the deploy's chain check."""
        return type(self).__name__

    def __enter__(self):
        return self

    def __exit__(self, *exc) -> None:
        self.close()


class InputDevice(ABC):
    """Operator intent. `now_s` is the loop's clock (simulated time in lockstep, the monotonic
    clock on the robot); devices time slew rates and staleness with it."""

    @abstractmethod
    def poll(self, now_s: float) -> Command: ...

    def observe(self, feedback: ExecutionFeedback) -> None:
        """The loop's feedback record (estimate, ground truth where there is one, goal verdicts,
        phase), given before every poll; the same instance each time, filled in place. Devices
        that steer by execution (a behaviour program) keep it; a device wrapping another passes
        it on."""

    @property
    def lost(self) -> bool:
        """True once the device is gone for good (the loop then stops the robot, then damps it)."""
        return False

    @property
    def lost_reason(self) -> str | None:
        """Why the device was lost (None while it is not, or when it cannot tell)."""
        return None

    def button_chords(self, action: str) -> list[str]:
        """The operator's buttons or keys bound to `action` ("estop", "start", ...), one 'a+b' chord
        each; [] for a device that maps no buttons (scripts, programs without an operator)."""
        return []

    def close(self) -> None:
        """Release the device."""

    def describe(self) -> str:
        """A short name for the device (video overlay, summaries)."""
        return type(self).__name__


class LineInput(InputDevice):
    """An input device that also takes typed lines (a terminal keyboard): instructions in English
    (g1_control/program/instructed.py)."""

    @abstractmethod
    def take_line(self) -> str | None:
        """The oldest line the operator submitted, or None."""

    def begin_line(self, prompt: str = "> ") -> None:
        """Open a line now, as if the operator had pressed the instruction key (to ask a question)."""


class WorldPoseEstimate(Protocol):
    """The robot's own world pose estimate in the scene frame (g1_control/estimation/localiser.py),
    which a generator that executes goals may steer by (Generator.steer_by)."""

    def scene_state(self, state: RobotState) -> RobotState:
        """`state` with the estimate as its base pose (base_pos_w_m, heading, velocity in scene axes)."""
        ...

    def object_positions(self) -> Mapping[str, np.ndarray]:
        """Named objects (boxes) seen by perception, their centres in the scene frame ({} without perception)."""
        ...

    def platforms_seen(self) -> Mapping[str, Platform]:
        """Platforms seen by perception, where it sees them in the scene frame ({} without perception)."""
        ...


class Generator(ABC):
    """Operator intent -> the whole-body plan for this tick. A generator that executes task goals
    (Command.tasks: g1_control/generator/goals/) reports on them through the attributes below,
    which the loop passes back to the input (ExecutionFeedback); the defaults are a generator
    without goals, always in the walking phase."""

    phase: str = PHASE_LOCOMOTION
    """PHASE_WHOLE_BODY while the generator holds the robot in a whole-body plan (a reach, a carry,
    a step), else PHASE_LOCOMOTION."""
    goal_status: Mapping[str, str] = NO_GOALS
    """goal_id -> "reached" | "failed", for each task goal finished so far (live: updated in place)."""
    goal_messages: Mapping[str, str] = NO_GOALS
    """goal_id -> why the goal failed."""
    goal_info: Mapping[str, Mapping[str, Any]] = NO_GOALS
    """goal_id -> what the generator recorded about the goal (kind, timing, status), for judging
    it after the run (g1_control/report/outcomes.py)."""
    goal_log: Sequence[tuple[float, str]] = ()
    """(t_s, text) notes of the execution layer as they came (goal started, failed and why), for reports."""
    plan_windows: Sequence[tuple[str, float, float]] = ()
    """(what, start t_s, end t_s) of each plan the execution layer made, in the state's time: on a wall
    clock, the stretches of loop ticks that ran while a plan was being made beside them (reports)."""

    def close(self) -> None:
        """Release what the generator holds beyond the loop (a goal planner's process)."""

    @abstractmethod
    def update(self, command: Command, state: RobotState) -> KinematicReference: ...

    def reset(self, state: RobotState) -> None:
        """Start over from `state`."""

    def steer_by(self, estimate: WorldPoseEstimate) -> None:
        """Place goals by `estimate` instead of the state's ground truth (the loop builder, where the
        launch file steers by the estimate); a generator without goals has nothing to place."""


class Retargeter(ABC):
    """The IK stage (the loop's: g1_control/ik/stage.py, IKStage). A reference that carries a plan
    feasible by construction (KinematicReference.feasible_plan) needs no solving."""

    @abstractmethod
    def solve(self, reference: KinematicReference, q_prev: np.ndarray) -> JointReference: ...


class Hands(ABC):
    """The loop's fingers stage (trackers/hands.py): the reference's grasps and finger angles to the
    hands, once per tracker tick after the body's safety stage."""

    @property
    @abstractmethod
    def tripped(self) -> str | None:
        """Why the fingers were damped (None: not)."""

    @abstractmethod
    def reset(self) -> None: ...

    @abstractmethod
    def update(self, ref: KinematicReference | None, now_s: float, body_faulted: bool) -> None:
        """Command the fingers from `ref`; damp them (latched) when the body's safety layer has."""


class Tracker(ABC):
    @abstractmethod
    def act(self, reference: JointReference, state: RobotState) -> MotorCommand: ...

    def reset(self, state: RobotState) -> None:
        """Clear internal memory (action history, phase)."""

    def observe(self, estimate: EstimatedState) -> None:
        """The state estimator's latest output (at the estimator's rate); trackers that close
        loops on the base's velocity keep it."""

    @property
    def command_limits(self) -> CommandLimits | None:
        """The operator command range this tracker can follow (None: no range of its own). The
        loop builder intersects it with the launch file's limits; teleop sticks scale to it."""
        return None

    @property
    def policy_command(self) -> np.ndarray | None:
        """(vx, vy, wz) the tracker actually asks its walking controller for, after its own
        shaping (e.g. velocity correction); None when it has no such command. Logged."""
        return None
