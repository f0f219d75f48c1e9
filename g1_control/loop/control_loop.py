"""The fixed-rate control loop: input -> estimator -> generator -> retargeter -> tracker ->
guard -> low-level stream, as scheduler stages at their own rates (see scheduler.py)."""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from g1_control.errors import InvalidCommandError, InvalidStateError, RetargetError
from g1_control.estimation.estimator import StateEstimator
from g1_control.estimation.localiser import Localiser
from g1_control.interfaces import Backend, Generator, Hands, InputDevice, Retargeter, Tracker
from g1_control.loop.rates import LoopRates
from g1_control.loop.scheduler import Scheduler, Stage
from g1_control.robot import g1
from g1_control.rotations import quat_to_rot_rows, tilt_rad, yaw_of
from g1_control.safety import SafetyConfig, SafetyFilter
from g1_control.safety.events import SafetyEvent
from g1_control.safety.fall import Fall, FallMonitor
from g1_control.types import Button, Command, ExecutionFeedback, JointReference, KinematicReference, RobotState


@dataclass
class LoopEvent:
    t_s: float
    kind: str
    detail: str
    trips: bool = False
    """True for the safety event that switched the robot to damping for good (SafetyEvent.trips)."""
    planned: bool = False
    """A planned ending (operator stop, end of the control time, a signal): not a fault."""

    @classmethod
    def of_safety(cls, event: SafetyEvent, loop_t_s: float) -> LoopEvent:
        """The loop's record of a safety event (its kind, detail and type flags kept as they are)."""
        return cls(loop_t_s, event.kind.value, event.detail, event.trips, event.planned)

    def __str__(self) -> str:
        return f"{self.kind}{' (damping)' if self.trips else ''}: {self.detail}"


def first_fault(events: list[dict]) -> dict | None:
    """The first unplanned trip among a run's events (LoopEvent dicts, as in summary.json), or None.
    Trips are found by their type (the `trips` flag), never by the wording of their detail."""
    return next((e for e in events if e.get("trips") and not e.get("planned")), None)


@dataclass
class RunLog:
    """Per-tracker-tick records, preallocated (no allocation in the loop). Without a sink it holds the
    whole run (capacity rows; later ticks are dropped). With a sink (a run folder, g1_control/launch/
    run_folder.py) it is one chunk: when full, a copy goes to sink() and the chunk starts over, so
    memory stays bounded however long the run."""

    capacity: int
    sink: Callable[[dict[str, np.ndarray]], None] | None = None
    n: int = 0
    t_s: np.ndarray = field(init=False)
    command: np.ndarray = field(init=False)          # operator (vx, vy, wz)
    policy_command: np.ndarray = field(init=False)   # after velocity correction
    velocity_est: np.ndarray = field(init=False)     # estimator (vx, vy, wz), heading frame
    velocity_true: np.ndarray = field(init=False)    # ground truth, heading frame (NaN on a robot)
    base_pos_m: np.ndarray = field(init=False)
    base_quat_wxyz: np.ndarray = field(init=False)   # IMU orientation (the sim's IMU sits on the pelvis)
    yaw_rad: np.ndarray = field(init=False)
    tilt_rad: np.ndarray = field(init=False)
    q_rad: np.ndarray = field(init=False)
    q_target_rad: np.ndarray = field(init=False)     # what the motors were sent (after the safety filter)
    q_ref_rad: np.ndarray = field(init=False)        # the tracker's reference posture (the plan after the IK)
    ref_root_pos_m: np.ndarray = field(init=False)   # the tracker's reference root position (world)
    ref_root_quat_wxyz: np.ndarray = field(init=False)  # the tracker's reference root orientation
    tau_nm: np.ndarray = field(init=False)
    late_s: np.ndarray = field(init=False)           # worst lateness of the wall-clock ticks since the last row
    style_id: np.ndarray = field(init=False)         # index into style_names of the operator's style
    style_names: list[str] = field(default_factory=list)

    def __post_init__(self) -> None:
        c, j = self.capacity, g1.NUM_JOINTS
        self.t_s = np.zeros(c)
        for name, width in (("command", 3), ("policy_command", 3), ("velocity_est", 3), ("velocity_true", 3),
                            ("base_pos_m", 3), ("base_quat_wxyz", 4), ("q_rad", j), ("q_target_rad", j),
                            ("q_ref_rad", j), ("ref_root_pos_m", 3), ("ref_root_quat_wxyz", 4), ("tau_nm", j)):
            setattr(self, name, np.full((c, width), np.nan))
        self.style_id = np.full(c, -1, dtype=np.int16)
        self.yaw_rad = np.full(c, np.nan)
        self.tilt_rad = np.full(c, np.nan)
        self.late_s = np.zeros(c)

    NAMES = ("t_s", "command", "policy_command", "velocity_est", "velocity_true", "base_pos_m", "base_quat_wxyz",
             "yaw_rad", "tilt_rad", "q_rad", "q_target_rad", "q_ref_rad", "ref_root_pos_m", "ref_root_quat_wxyz",
             "tau_nm", "late_s", "style_id")
    """The per-tick arrays (style_names, the names behind style_id, is not per tick)."""

    def arrays(self) -> dict[str, np.ndarray]:
        out = {name: getattr(self, name)[: self.n] for name in self.NAMES}
        out["style_names"] = np.array(self.style_names, dtype=str)
        return out

    def flush(self) -> None:
        """Hand the rows so far to the sink (a copy) and start a new chunk (style_names stay)."""
        if self.sink is not None and self.n:
            self.sink({name: getattr(self, name)[: self.n].copy() for name in self.NAMES})
            self.n = 0

    def style_index(self, name: str) -> int:
        if name not in self.style_names:
            self.style_names.append(name)
        return self.style_names.index(name)


class ControlLoop:
    """One tick: input -> estimator -> generator -> retargeter -> tracker -> safety -> low-level.

    Every motor command passes the SafetyFilter (clamps to limits; damping for good on a fall,
    stale or non-finite state, NaN output, e-stop, lost operator input, an IK without a solution for
    longer than safety.ik_hold_ticks ticks, ...), in simulation as on the robot. Time for the safety checks is the loop's own clock: simulated time in lockstep,
    the monotonic clock otherwise (the robot's states are stamped with it on arrival).

    Falls are judged every tracker tick by a FallMonitor (g1_control/safety/fall.py) from the
    simulator's ground truth (pelvis height, ground contacts) or, on the robot, from the IMU and
    the estimator's pelvis height; the first fall damps the robot like any trip, and the
    monitor keeps watching after another trip (a damped robot that collapses has fallen).
    """

    def __init__(self, backend: Backend, input_device: InputDevice, generator: Generator, retargeter: Retargeter,
                 tracker: Tracker, rates: LoopRates | None = None, *, estimator: StateEstimator | None = None,
                 wallclock: bool = False, max_tilt_rad: float = 1.0, log_capacity: int = 0,
                 safety: SafetyFilter | None = None, falls: FallMonitor | None = None,
                 localiser: Localiser | None = None, hands: Hands | None = None):
        self.backend, self.input, self.generator = backend, input_device, generator
        self.retargeter, self.tracker = retargeter, tracker
        self.rates = rates or LoopRates()
        self.estimator = estimator or StateEstimator()
        self.localiser = localiser
        """The robot's world pose estimate (estimation/localiser.py), updated after the estimator; None:
        the loop runs none (goals and programs steer by the simulator's ground truth)."""
        self.hands = hands
        """The Dex3 fingers' stage (trackers/hands.py): the reference's grasps and finger angles through the
        hands' safety layer; None: a robot without hands (or hands the loop does not drive)."""
        self.safety = safety or SafetyFilter(SafetyConfig(max_tilt_rad=max_tilt_rad))
        self.falls = falls or FallMonitor(max_tilt_rad=self.safety.config.max_tilt_rad)
        self.command = Command()
        self.state = RobotState()
        self.motor_command = self.safety.damping()
        self._tracker_command = self.motor_command
        self.invalid_commands = 0
        self.events: list[LoopEvent] = []
        self.on_record: Callable[[dict], None] | None = None
        """Called with each event as a JSON-able dict (a run folder's events.jsonl)."""
        self.chain: dict[str, str] = {}
        """What each stage is (set by g1_control/launch/builder.py): the same in a deploy's dry run and on the robot."""
        self.log = RunLog(max(1, log_capacity))
        self.feedback = ExecutionFeedback()
        """What execution reports back to the input (estimate, ground truth, goal verdicts, phase):
        one record, filled in place before every input poll and given to InputDevice.observe."""
        r = self.rates
        stages = [
            Stage("input", r.input_hz, self._input),
            Stage("estimator", r.estimator_hz, self._estimate),
            Stage("generator", r.tracker_hz, self._generate),
            Stage("retargeter", r.tracker_hz, self._retarget),
            Stage("tracker", r.tracker_hz, self._track),
            Stage("safety", r.tracker_hz, self._safety),
            *([Stage("hands", r.tracker_hz, self._hands)] if hands is not None else []),
            Stage("lowlevel", r.lowlevel_hz, self._lowlevel, batch=self._lowlevel_ticks if backend.lockstep else None),
            Stage("log", r.tracker_hz, self._log),
        ]
        self.scheduler = Scheduler(r.lowlevel_hz, stages, wallclock=wallclock)
        if backend.lockstep:
            # A simulator paced by the wall clock steps the ticks a stall made the scheduler skip, when it
            # skips them, fed as the robot link would (_skipped_ticks): the world does not wait for a late controller,
            # and the next state is current (else every skipped tick would age the state for good, until
            # the stale-state check damps a robot that was never stale).
            self.scheduler.on_skip = self._skipped_ticks
        # The latest generator and retargeter outputs (None before their first tick: within a tick the
        # stages run in the order listed above, so each is set before the next stage reads it).
        self._kin_ref: KinematicReference | None = None
        self._joint_ref: JointReference | None = None
        self._state_tick = -1
        self.safety.on_event = self._on_safety_event

    # -- lifecycle ---------------------------------------------------------------------------------
    def reset(self) -> RobotState:
        self.state = self.backend.reset()
        self.falls.reset()
        self.estimator.reset(self.state)
        if self.localiser is not None:
            self.localiser.reset(self.state)
        self.tracker.reset(self.state)
        self.generator.reset(self.state)
        if self.hands is not None:
            self.hands.reset()
        return self.state

    def run(self, duration_s: float, progress=None) -> int:
        n = round(duration_s * self.rates.lowlevel_hz)
        return self.scheduler.run(n, progress=progress)

    @property
    def time_s(self) -> float:
        return self.scheduler.time_s

    def _event(self, kind: str, detail: str, record: dict | None = None, event: LoopEvent | None = None) -> None:
        self.events.append(event or LoopEvent(self.time_s, kind, detail))
        if self.on_record is not None:
            self.on_record(record or {"type": "loop", "t_s": self.time_s, "kind": kind, "detail": detail})

    def now_s(self) -> float:
        return self.time_s if self.backend.lockstep else time.monotonic()

    @property
    def faulted(self) -> bool:
        return self.safety.tripped

    @property
    def fall(self) -> Fall | None:
        """The first fall (g1_control/safety/fall.py), or None."""
        return self.falls.fall

    @property
    def fell(self) -> bool:
        return self.falls.fall is not None

    def _on_safety_event(self, event: SafetyEvent) -> None:
        self._event(event.kind.value, event.detail,
                    {"type": "safety", "t_s": event.t_s, "loop_t_s": self.time_s, "kind": event.kind.value,
                     "detail": event.detail, "trips": event.trips, "planned": event.planned},
                    LoopEvent.of_safety(event, self.time_s))

    # -- stages --------------------------------------------------------------------------------------
    def _input(self) -> None:
        now = self.now_s()
        self._feed_back(now)
        command = self.input.poll(now)
        if self.input.lost:
            # A lost device is no input at all: the safety layer stops the robot, then damps it.
            self.command = self.safety.vet_input(None, now)
            return
        try:
            command.validate()
        except InvalidCommandError as exc:
            # Keep the last good command; the bad one never reaches the tracker.
            self.invalid_commands += 1
            if self.invalid_commands == 1 or self.invalid_commands % 100 == 0:
                self._event("invalid_command", str(exc))
            self.command = self.safety.vet_input(None, now)
            return
        if Button.DAMP in command.buttons:
            self.safety.estop("damp pressed on the operator input", now)
        self.command = self.safety.vet_input(command, now)

    def _feed_back(self, now: float) -> None:
        """Fill the feedback record from the latest state, estimate and generator report (no
        allocation: references to the loop's own objects) and hand it to the input."""
        fb, s, g = self.feedback, self.state, self.generator
        fb.t_s = now
        fb.estimate = self.estimator.estimate
        fb.state = s
        fb.truth = s if s.base_pos_w_m is not None else None
        fb.goal_status, fb.goal_messages, fb.phase = g.goal_status, g.goal_messages, g.phase
        fb.pose = self.localiser.pose if self.localiser is not None else None
        self.input.observe(fb)

    def _read_state(self) -> RobotState | None:
        """The robot's state for this tick (read once per tick, shared by the stages)."""
        tick = self.scheduler.tick_index
        if self._state_tick == tick:
            return None if self.faulted else self.state
        self._state_tick = tick
        state = self.backend.read_state()
        try:
            self.state = state.validate()
        except InvalidStateError as exc:
            self._fault(f"invalid robot state: {exc}")
            return None
        return self.state

    def _estimate(self) -> None:
        state = self._read_state()
        if state is not None:
            self.tracker.observe(self.estimator.update(state))
            self._localise(state)

    def _localise(self, state: RobotState) -> None:
        """The world pose estimate after the estimator (it shares the estimator's kinematics)."""
        if self.localiser is not None:
            self.localiser.update(state)

    def _generate(self) -> None:
        self._kin_ref = self.generator.update(self.command, self.state)

    def _retarget(self) -> None:
        assert self._kin_ref is not None  # the generator stage ran first
        try:
            joint_ref = self.retargeter.solve(self._kin_ref, self.state.q_rad)
        except RetargetError as exc:
            # No reference this tick (the IK's QP failed even relaxed): the tracker keeps the last good
            # one for up to safety.ik_hold_ticks ticks in a row; longer, or with none to keep, damps.
            self.safety.report_ik_failure(f"{type(exc).__name__}: {exc}", self.now_s(),
                                          can_hold=self._joint_ref is not None)
            return
        self._joint_ref = joint_ref
        self.safety.report_ik_solved()

    def _track(self) -> None:
        if self.faulted:
            return
        state = self._read_state()
        if state is None:
            return
        assert self._joint_ref is not None  # the retargeter stage ran first
        self._tracker_command = self.tracker.act(self._joint_ref, state)

    def _safety(self) -> None:
        # Robot links count states dropped for a bad CRC; a burst of them trips the filter. A second
        # publisher of the robot's state (or another writer of its commands) trips it at once.
        self.safety.report_crc_errors(self.backend.bad_crc, self.now_s())
        self.safety.report_peers(self.backend.peer_fault, self.now_s())
        # Missed deadlines endanger a robot that runs on its own; a simulator we step just slows down.
        # A tick counts as an overrun when it finished more than safety.overrun_lateness_s late.
        if self.scheduler.wallclock and not self.backend.lockstep:
            late = self.scheduler.take_lateness()
            self.safety.report_deadline(late > self.safety.config.overrun_lateness_s, self.now_s(),
                                        f"{late * 1000:.0f} ms late" if late > 0 else "")
        now = self.now_s()
        self.motor_command = self.safety.filter(self._tracker_command, self.state, now)
        if self.falls.fall is None:
            self._check_fall(now)

    def _hands(self) -> None:
        assert self.hands is not None
        self.hands.update(self._kin_ref, self.now_s(), self.faulted)

    def _check_fall(self, now: float) -> None:
        s = self.state
        # Ground truth where the simulator gives it, else the estimator's leg-kinematics height.
        height = float(s.base_pos_w_m[2]) if s.base_pos_w_m is not None else self.estimator.estimate.pelvis_height_m
        fall = self.falls.update(now, s.imu_quat_wxyz, height, self.backend.ground_contacts())
        if fall is not None:
            self._event("fall", fall.detail)
            self.safety.report_fall(fall.detail, now)
            self.motor_command = self.safety.damping()

    def _fault(self, detail: str) -> None:
        self.safety.estop(detail, self.now_s())
        self.motor_command = self.safety.damping()

    def _lowlevel(self) -> None:
        if self.backend.lockstep:
            self.backend.step_ticks(self.motor_command, self.scheduler.dt_s, 1)  # write_command, then step
        else:
            self.backend.write_command(self.motor_command)

    def _lowlevel_ticks(self, n: int) -> None:
        """n low-level ticks in a row with nothing else due (lockstep; see loop/scheduler.py)."""
        self.backend.step_ticks(self.motor_command, self.scheduler.dt_s, n)

    def _skipped_ticks(self, n: int) -> None:
        """The n ticks a stall made a wall-clock simulator skip, fed as the robot link feeds the motors:
        the last command for its life (safety.command_hold_ticks tracker ticks), then its hold form
        (MotorCommand.hold_form: no feedforward torque, no velocity target; hardware/link_backend.py)."""
        command, dt = self.motor_command, self.scheduler.dt_s
        ticks = self.safety.config.command_hold_ticks
        life = round(ticks * self.rates.lowlevel_hz / self.rates.tracker_hz) if ticks > 0 else n
        if n <= life or not (command.tau_nm.any() or command.dq_radps.any()):
            self.backend.step_ticks(command, dt, n)
            return
        self.backend.step_ticks(command, dt, life)
        self.backend.step_ticks(command.hold_form(), dt, n - life)

    def _log(self) -> None:
        log = self.log
        i = log.n
        if i >= log.capacity:
            if log.sink is None:
                return
            log.flush()
            i = 0
        s, est = self.state, self.estimator.estimate
        quat = s.imu_quat_wxyz
        log.t_s[i] = self.time_s
        log.late_s[i] = self.scheduler.take_log_lateness()
        command = log.command[i]
        command[:] = (self.command.vx_mps, self.command.vy_mps, self.command.wz_radps)
        policy_command = self.tracker.policy_command
        log.policy_command[i] = command if policy_command is None else policy_command
        log.velocity_est[i] = est.heading_velocity
        yaw = yaw_of(quat)
        log.yaw_rad[i] = yaw
        log.base_quat_wxyz[i] = quat
        log.tilt_rad[i] = tilt_rad(quat)
        if s.base_linvel_w_mps is not None:
            c, sn = math.cos(yaw), math.sin(yaw)
            vx, vy, _ = s.base_linvel_w_mps.tolist()
            r2, (gx, gy, gz) = quat_to_rot_rows(quat)[2], s.imu_gyro_radps.tolist()
            wz = r2[0] * gx + r2[1] * gy + r2[2] * gz  # world yaw rate
            log.velocity_true[i] = (c * vx + sn * vy, -sn * vx + c * vy, wz)
            log.base_pos_m[i] = s.base_pos_w_m
        log.q_rad[i] = s.q_rad
        log.q_target_rad[i] = self.motor_command.q_rad
        if self._joint_ref is not None:
            log.q_ref_rad[i] = self._joint_ref.q_rad
            log.ref_root_pos_m[i] = self._joint_ref.root_pos_w_m
            log.ref_root_quat_wxyz[i] = self._joint_ref.root_quat_wxyz
        log.style_id[i] = log.style_index(self.command.style)
        log.tau_nm[i] = s.tau_nm
        log.n = i + 1
