"""The deploy state machine, as the Tracker of the control loop (so every command it makes still
passes the loop's SafetyFilter):

    zero_torque --start--> ramp (to the policy's default pose, >= 2 s) --> hold (>= min_hold_s) --run--> control
         any state --stop / e-stop / damp / safety trip / signal / exit--> damping (for good)

Operator buttons come from the launch file's input device (Unitree remote: start, A = run,
B = stop, L1+R1 = e-stop); with `auto` (`g1 deploy --yes`) start and run are answered after
DeployConfig.auto_start_s / auto_run_s. Damping is the SafetyFilter's one-way trip: a stop is an
e-stop with the reason "operator stop", and only a new deploy resumes control.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from dataclasses import dataclass
from enum import Enum

import numpy as np

from g1_control.interfaces import InputDevice, Tracker
from g1_control.launch.schema import DeployConfig
from g1_control.safety import SafetyFilter
from g1_control.teleop.gamepad_script import ScriptedGamepad
from g1_control.teleop.scripted import ScriptedInput
from g1_control.types import (
    Button,
    Command,
    CommandLimits,
    EstimatedState,
    ExecutionFeedback,
    JointReference,
    MotorCommand,
    RobotState,
)

log = logging.getLogger("g1_control.deploy")


class DeployState(str, Enum):
    ZERO_TORQUE = "zero_torque"
    RAMP = "ramp"
    HOLD = "hold"
    CONTROL = "control"
    DAMPING = "damping"


@dataclass(frozen=True)
class Transition:
    t_s: float
    source: DeployState
    target: DeployState
    reason: str

    def __str__(self) -> str:
        return f"{self.source.value} -> {self.target.value}: {self.reason}"


class OperatorButtons(InputDevice):
    """The launch file's input device, passed through unchanged, with every button press kept
    until the state machine takes it (the input stage may poll several times per tracker tick,
    and a press is present on one poll only)."""

    def __init__(self, inner: InputDevice):
        self.inner = inner
        self._pressed: set[str] = set()
        self.timeline_clock: Callable[[], float] | None = None
        """For a scripted input (a timeline or a gamepad script): its clock, which starts when control
        starts (the DeployTracker's control_elapsed_s); live devices keep the loop's clock."""
        self._scripted = isinstance(inner, (ScriptedInput, ScriptedGamepad))

    @property
    def lost(self) -> bool:
        return self.inner.lost

    @property
    def lost_reason(self) -> str | None:
        return self.inner.lost_reason

    def button_chords(self, action: str) -> list[str]:
        return self.inner.button_chords(action)

    def observe(self, feedback: ExecutionFeedback) -> None:
        self.inner.observe(feedback)

    def poll(self, now_s: float) -> Command:
        if self._scripted and self.timeline_clock is not None:
            now_s = self.timeline_clock()
        command = self.inner.poll(now_s)
        if command.buttons:
            self._pressed |= command.buttons
        return command

    def take(self) -> frozenset[str]:
        pressed, self._pressed = frozenset(self._pressed), set()
        return pressed

    def close(self) -> None:
        self.inner.close()


def smooth_step(x: float) -> float:
    """0 -> 1 with zero slope at both ends (no velocity jump when the ramp starts or ends)."""
    x = min(max(x, 0.0), 1.0)
    return 0.5 - 0.5 * float(np.cos(np.pi * x))


class DeployTracker(Tracker):
    """Wraps the policy tracker: zero torque, ramp and hold before it, damping after it."""

    def __init__(self, policy: Tracker, default_q_rad: np.ndarray, kp: np.ndarray, kd: np.ndarray,
                 safety: SafetyFilter, clock: Callable[[], float], config: DeployConfig | None = None, *,
                 buttons: OperatorButtons | None = None, auto: bool = False, control_s: float | None = None,
                 on_transition: Callable[[Transition], None] | None = None):
        self.policy, self.safety, self.clock = policy, safety, clock
        self.config = config or DeployConfig()
        self.buttons, self.auto, self.control_s = buttons, auto, control_s
        self.on_transition = on_transition
        self.default_q_rad = np.asarray(default_q_rad, dtype=float).copy()
        self.state = DeployState.ZERO_TORQUE
        self.transitions: list[Transition] = []
        self.entered_s: float | None = None
        self.control_started_s: float | None = None
        n = self.default_q_rad.size
        self._zero_torque = MotorCommand(q_rad=np.zeros(n), kp=np.zeros(n), kd=np.zeros(n))
        self._pose = MotorCommand(q_rad=self.default_q_rad.copy(), kp=np.asarray(kp, float).copy(),
                                  kd=np.asarray(kd, float).copy())
        self._ramp_from = self.default_q_rad.copy()
        self._run_requested = False
        self.ignored: list[str] = []

    # The wrapped tracker sees the estimator's output and reports its command, as it would unwrapped.
    def observe(self, estimate: EstimatedState) -> None:
        self.policy.observe(estimate)

    @property
    def policy_command(self) -> np.ndarray | None:
        return self.policy.policy_command

    @property
    def command_limits(self) -> CommandLimits | None:
        return self.policy.command_limits

    def reset(self, state: RobotState | None = None) -> None:
        """Start over in zero torque (a deploy runs the machine once; reset is for the loop's reset)."""
        self.state = DeployState.ZERO_TORQUE
        self.entered_s = None

    def control_elapsed_s(self) -> float:
        """Seconds since control began (0 before): the clock of a scripted command timeline."""
        return 0.0 if self.control_started_s is None else max(0.0, self.clock() - self.control_started_s)

    def time_in_state_s(self, now: float) -> float:
        """Seconds since the current state was entered (0 before the machine's first tick)."""
        return 0.0 if self.entered_s is None else now - self.entered_s

    def _go(self, target: DeployState, reason: str, now: float) -> None:
        transition = Transition(now, self.state, target, reason)
        self.transitions.append(transition)
        self.state, self.entered_s = target, now
        log.info("deploy: %s", transition)
        if self.on_transition is not None:
            self.on_transition(transition)

    def observe_safety(self, now: float) -> bool:
        """Enter damping if the safety layer tripped; True once in damping. The loop stops calling
        act() after a trip (it sends damping itself), so its driver calls this every tick."""
        trip = self.safety.trip_event
        if self.state != DeployState.DAMPING and trip is not None:  # i.e. self.safety.tripped
            self._go(DeployState.DAMPING, f"{trip.kind.value}: {trip.detail}", now)
        return self.state == DeployState.DAMPING

    def _step_machine(self, state: RobotState, now: float) -> None:
        if self.entered_s is None:
            self.entered_s = now
        if self.observe_safety(now):
            return
        pressed = self.buttons.take() if self.buttons is not None else frozenset()
        in_state = now - self.entered_s
        cfg = self.config
        if Button.STOP in pressed:
            self.safety.estop("operator stop", now, planned=True)
            self._go(DeployState.DAMPING, "operator stop", now)
        elif self.state == DeployState.ZERO_TORQUE:
            if Button.START in pressed or (self.auto and in_state >= cfg.auto_start_s):
                self._ramp_from = state.q_rad.copy()
                self._go(DeployState.RAMP, "operator start" if Button.START in pressed else "start (--yes)", now)
            elif Button.RUN in pressed:
                self.ignored.append("run ignored in zero_torque: press start first")
        elif self.state == DeployState.RAMP:
            if in_state >= cfg.ramp_s:
                self._go(DeployState.HOLD, f"default pose reached ({cfg.ramp_s:.1f} s ramp)", now)
            elif Button.RUN in pressed:
                self.ignored.append("run ignored during the ramp: wait for hold")
        elif self.state == DeployState.HOLD:
            # A run pressed early waits for min_hold_s: the robot settles on the pose before the policy.
            self._run_requested |= Button.RUN in pressed
            if in_state >= cfg.min_hold_s and (self._run_requested or (self.auto and in_state >= cfg.auto_run_s)):
                self.policy.reset(state)
                self.control_started_s = now
                self._go(DeployState.CONTROL, "operator run" if self._run_requested else "run (--yes)", now)
        elif self.state == DeployState.CONTROL and self.control_s is not None and in_state >= self.control_s:
            self.safety.estop(f"control time over ({self.control_s:.1f} s, launch duration_s)", now, planned=True)
            self._go(DeployState.DAMPING, f"control time over ({self.control_s:.1f} s)", now)

    def act(self, reference: JointReference, state: RobotState) -> MotorCommand:
        now = self.clock()
        self._step_machine(state, now)
        s = self.state
        if s == DeployState.CONTROL:
            return self.policy.act(reference, state)
        if s == DeployState.RAMP:
            alpha = smooth_step(self.time_in_state_s(now) / self.config.ramp_s)
            self._pose.q_rad[:] = self._ramp_from + alpha * (self.default_q_rad - self._ramp_from)
            return self._pose
        if s == DeployState.HOLD:
            self._pose.q_rad[:] = self.default_q_rad
            return self._pose
        if s == DeployState.ZERO_TORQUE:
            return self._zero_torque
        return self.safety.damping()

    @property
    def sequence(self) -> list[str]:
        """States visited, in order."""
        return [DeployState.ZERO_TORQUE.value] + [t.target.value for t in self.transitions]
