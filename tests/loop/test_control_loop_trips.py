"""The loop's trip path on a stand-in robot whose link reports are set by the test (issue 26: the
mutation run's loop group): bad CRCs, a foreign peer, missed deadlines (on a wall-clock robot, not
on a simulator we step), falls judged from ground truth or from the estimator, an invalid state,
and the records each event leaves (events and the run folder's event records)."""

from __future__ import annotations

import time

import numpy as np
import pytest

from g1_control.estimation.localiser import Localiser
from g1_control.estimation.pose import LegOdometry
from g1_control.generator.velocity import VelocityReferenceGenerator
from g1_control.ik.stage import IKStage
from g1_control.interfaces import Backend, InputDevice, Tracker
from g1_control.loop.control_loop import ControlLoop
from g1_control.robot import g1
from g1_control.safety import SafetyConfig, SafetyEventKind, SafetyFilter
from g1_control.types import Button, Command, MotorCommand, RobotState, TaskGoal


class StandInRobot(Backend):
    """A robot standing still on its default pose, whose link reports (bad CRCs, peers, contacts)
    and pelvis height the test sets. Lockstep: it advances in step(); wall clock: every read is a
    new sample stamped with time.monotonic(), as a robot link stamps them on arrival."""

    def __init__(self, lockstep: bool = True, pelvis_z_m: float | None = 0.78):
        self.lockstep = lockstep
        self.t_s, self.tick = 0.0, 0
        self.pelvis_z_m = pelvis_z_m
        self.q_rad = g1.DEFAULT_Q_RAD.copy()
        self.crc, self.peer, self.contacts = 0, None, ()
        self.corrupt = None
        """Set by a test: a function that spoils each state read from then on."""
        self.states: list[RobotState] = []

    def reset(self) -> RobotState:
        return self.read_state()

    def read_state(self) -> RobotState:
        if not self.lockstep:
            self.t_s, self.tick = time.monotonic(), self.tick + 1
        state = RobotState(t_s=self.t_s, q_rad=self.q_rad.copy(), tick=self.tick,
                           base_pos_w_m=None if self.pelvis_z_m is None else np.array([0.0, 0.0, self.pelvis_z_m]))
        if self.corrupt is not None:
            self.corrupt(state)
        self.states.append(state)
        return state

    def write_command(self, command: MotorCommand) -> None:
        self.last_command = command

    def step(self, dt_s: float) -> None:
        self.t_s, self.tick = self.t_s + dt_s, self.tick + 1

    def ground_contacts(self):
        return self.contacts

    @property
    def bad_crc(self) -> int:
        return self.crc

    @property
    def peer_fault(self) -> str | None:
        return self.peer

    def close(self) -> None:
        pass


class Hold(Tracker):
    """Holds the default pose; records the states it acts on."""

    def __init__(self):
        self.states: list[RobotState] = []

    def act(self, reference, state) -> MotorCommand:
        self.states.append(state)
        return MotorCommand(q_rad=g1.DEFAULT_Q_RAD.copy(), kp=g1.KP_DEFAULT.copy(), kd=g1.KD_DEFAULT.copy())


class Still(InputDevice):
    def __init__(self, commands=()):
        self.commands = list(commands)

    def poll(self, now_s: float) -> Command:
        return self.commands.pop(0) if self.commands else Command()


def _loop(robot=None, device=None, **kw) -> tuple[ControlLoop, StandInRobot, list[dict]]:
    robot = robot or StandInRobot()
    loop = ControlLoop(robot, device or Still(), VelocityReferenceGenerator(), IKStage(), Hold(), **kw)
    records: list[dict] = []
    loop.on_record = records.append
    loop.reset()
    return loop, robot, records


def test_a_burst_of_bad_crcs_trips_at_the_loops_time():
    loop, robot, _records = _loop()
    loop.run(0.1)
    robot.crc = 5
    loop.run(0.02)
    trip = loop.safety.trip_event
    assert trip.kind == SafetyEventKind.CRC_BURST and trip.detail.endswith("(5 in total)")
    assert 0.1 <= trip.t_s <= 0.12
    assert np.all(loop.motor_command.kp == 0)


def test_a_foreign_peer_trips_at_once_naming_it_and_is_recorded():
    loop, robot, records = _loop()
    loop.run(0.1)
    robot.peer = "a second publisher of rt/lowstate"
    loop.run(0.02)
    trip = loop.safety.trip_event
    assert trip.kind == SafetyEventKind.FOREIGN_PEER and trip.detail == "a second publisher of rt/lowstate"
    assert 0.1 <= trip.t_s <= 0.12
    assert records == [{"type": "safety", "t_s": trip.t_s, "loop_t_s": loop.events[0].t_s, "kind": "foreign_peer",
                        "detail": "a second publisher of rt/lowstate", "trips": True, "planned": False}]
    assert (loop.events[0].kind, loop.events[0].detail, loop.events[0].trips) == ("foreign_peer", trip.detail, True)


def _wallclock_loop(lockstep: bool, late_s: float, monkeypatch, wallclock=True, stale_state_s: float = 0.05):
    loop, _robot, _records = _loop(StandInRobot(lockstep=lockstep), wallclock=wallclock,
                                   safety=SafetyFilter(SafetyConfig(stale_state_s=stale_state_s)))
    monkeypatch.setattr(loop.scheduler, "take_lateness", lambda: late_s)
    return loop


def test_late_ticks_on_a_robot_trip_after_the_overrun_burst_naming_the_lateness(monkeypatch):
    loop = _wallclock_loop(False, 0.9, monkeypatch)
    loop.run(0.1)  # 5 tracker ticks, each reported 900 ms late
    trip = loop.safety.trip_event
    assert trip is not None and trip.kind == SafetyEventKind.DEADLINE_OVERRUNS
    assert trip.detail == "5 deadline overruns within 1.0 s (900 ms late)"
    assert abs(trip.t_s - time.monotonic()) < 5.0, "judged on the robot's (monotonic) clock"


def test_ticks_exactly_on_time_are_not_overruns(monkeypatch):
    loop = _wallclock_loop(False, 0.0, monkeypatch)
    loop.run(0.2)
    assert not loop.faulted, loop.events


@pytest.mark.parametrize("lockstep, wallclock", [(True, True), (False, False)])
def test_no_deadline_is_judged_on_a_simulator_we_step_or_without_the_wall_clock(lockstep, wallclock, monkeypatch):
    # A lockstep robot on the wall clock skips the ticks a slow host misses (mutmut's stats run, a loaded
    # host): its state then ages past 50 ms. What is judged here is the deadline, not the state's age.
    loop = _wallclock_loop(lockstep, 0.9, monkeypatch, wallclock=wallclock, stale_state_s=10.0)
    loop.run(0.2)
    assert not loop.faulted, loop.events


def test_a_low_pelvis_in_the_ground_truth_is_a_fall_even_if_the_legs_look_standing():
    loop, robot, records = _loop(StandInRobot(pelvis_z_m=0.78))
    loop.run(0.1)
    assert not loop.fell
    robot.pelvis_z_m = 0.3  # the simulator's pelvis sank; the joint angles still say "standing"
    loop.run(0.02)
    assert loop.fell and loop.fall.kind == "pelvis_low" and loop.fall.detail == "pelvis at 0.30 m (limit 0.40)"
    trip = loop.safety.trip_event
    assert (trip.kind, trip.detail) == (SafetyEventKind.FALL, loop.fall.detail)
    assert trip.t_s == loop.fall.t_s and 0.1 <= trip.t_s <= 0.12
    fall_event = next(e for e in loop.events if e.kind == "fall")
    assert fall_event.detail == loop.fall.detail
    assert {"type": "loop", "t_s": fall_event.t_s, "kind": "fall", "detail": loop.fall.detail} in records
    assert np.all(loop.motor_command.kp == 0)


def test_a_robot_without_ground_truth_is_judged_by_the_estimators_height():
    loop, _robot, _ = _loop(StandInRobot(pelvis_z_m=None))
    loop.run(0.2)
    assert loop.estimator.estimate.pelvis_height_m > 0.6 and not loop.fell and not loop.faulted
    loop.falls.config = type(loop.falls.config)(min_pelvis_height_m=loop.estimator.estimate.pelvis_height_m + 0.01)
    loop.run(0.02)
    assert loop.fell and loop.fall.kind == "pelvis_low"


def test_a_body_on_the_ground_is_a_fall_naming_it():
    loop, robot, _ = _loop()
    loop.run(0.1)
    robot.contacts = ("left_knee_link",)
    loop.run(0.02)
    assert loop.fell and loop.fall.detail == "left_knee_link on the ground"
    assert loop.safety.trip_event.detail == "left_knee_link on the ground"


def test_an_invalid_state_trips_naming_it():
    loop, robot, _ = _loop()
    loop.run(0.11)  # the next state read (100 Hz) falls between two tracker ticks (50 Hz)
    robot.q_rad[3] = np.nan
    loop.run(0.01)
    trip = loop.safety.trip_event
    assert trip.kind == SafetyEventKind.ESTOP and trip.detail.startswith("invalid robot state: ")
    assert "q_rad" in trip.detail
    sent = robot.last_command
    assert np.all(sent.kp == 0) and np.all(sent.kd > 0), "damping goes out at once, not at the next tracker tick"


def _nan_acc(state: RobotState) -> None:
    state.imu_acc_mps2[2] = np.nan


def _long_quat(state: RobotState) -> None:
    state.imu_quat_wxyz = np.array([1.05, 0.0, 0.0, 0.0])  # inside the filter's own 0.1 norm slack


def _short_joints(state: RobotState) -> None:
    state.q_rad = state.q_rad[:23]


@pytest.mark.parametrize(("corrupt", "message"), [
    (_nan_acc, "RobotState.imu_acc_mps2 contains NaN or inf"),
    (_long_quat, "RobotState.imu_quat_wxyz has norm 1.0500; expected 1"),
    (_short_joints, "RobotState.q_rad has shape (23,); expected (29,)"),
])
def test_a_corrupt_state_trips_naming_the_field_and_damps_at_once(corrupt, message):
    """Every state the loop reads is validated before the estimator sees it: a NaN accelerometer,
    a quaternion 5 % long, a joint array of the wrong length each trip naming the field, and
    damping goes out on that tick."""
    loop, robot, _ = _loop()
    loop.run(0.11)  # the next state read (100 Hz) falls between two tracker ticks (50 Hz)
    robot.corrupt = corrupt
    loop.run(0.01)
    trip = loop.safety.trip_event
    assert trip is not None and (trip.kind, trip.detail) == (SafetyEventKind.ESTOP, f"invalid robot state: {message}")
    sent = robot.last_command
    assert np.all(sent.kp == 0) and np.all(sent.kd > 0)


def test_the_tracker_acts_on_the_state_the_estimator_read_once_per_tick():
    loop, robot, _ = _loop()
    loop.run(0.2)  # 10 tracker ticks; the estimator runs at 100 Hz
    tracked = loop.tracker.states
    assert len(tracked) == 10 and all(any(s is r for r in robot.states) for s in tracked)
    assert len(robot.states) == 1 + 20, "one read per estimator tick (plus reset's), shared with the tracker"


def test_invalid_commands_leave_loop_records():
    loop, _, records = _loop(device=Still([Command(vx_mps=float("nan"))]))
    loop.run(0.02)
    assert records == [{"type": "loop", "t_s": 0.0, "kind": "invalid_command", "detail": loop.events[0].detail}]
    assert "vx_mps is nan" in records[0]["detail"]


@pytest.mark.parametrize(("bad", "message"), [
    (Command(pelvis_height_m=float("nan")), "Command.pelvis_height_m is nan; it must be a finite number"),
    (Command(buttons=frozenset({"estp"})), "Command has unknown buttons ['estp']"),
    (Command(tasks=[TaskGoal("reach", goal_id="g", pos_w_m=np.array([0.4, np.nan, 1.0]))]),
     "TaskGoal 'g' (reach) has position"),
])
def test_a_malformed_command_is_dropped_naming_the_field(bad, message):
    """A NaN pelvis height, a misspelt button or a goal at NaN never reaches the generator: the
    command is counted and recorded as invalid (naming the field) and the previous one stays in force."""
    loop, _, records = _loop(device=Still([Command(vx_mps=0.2), bad]))
    loop.run(0.02)
    assert loop.invalid_commands == 1 and [e.kind for e in loop.events] == ["invalid_command"]
    assert message in loop.events[0].detail and records[0]["detail"] == loop.events[0].detail
    assert loop.command.vx_mps == 0.2 and loop.command.pelvis_height_m is None and not loop.command.tasks
    assert not loop.faulted


def test_the_damp_button_damps_at_once():
    loop, robot, _ = _loop(device=Still([Command(vx_mps=0.2)] * 5 + [Command(buttons=frozenset({Button.DAMP}))]))
    loop.run(0.1)
    trip = loop.safety.trip_event
    assert trip is not None and (trip.kind, trip.detail) == (SafetyEventKind.ESTOP, "damp pressed on the operator input")
    assert abs(trip.t_s - 0.05) < 1e-9
    assert np.all(robot.last_command.kp == 0) and np.all(robot.last_command.kd > 0)


class LostAfter(InputDevice):
    """Walks at 0.3 m/s; lost after `n` polls, and still returns the last command, as a device
    that keeps its stale reading does."""

    def __init__(self, n: int):
        self.n, self.polls = n, 0

    @property
    def lost(self) -> bool:
        return self.polls > self.n

    def poll(self, now_s: float) -> Command:
        self.polls += 1
        return Command(vx_mps=0.3)


def test_a_lost_device_is_no_input_whatever_it_still_returns():
    """Once a device says it is lost, its commands are not acted on: the robot stops after
    safety.input_zero_velocity_s and is damped after safety.input_lost_s."""
    loop, robot, _ = _loop(device=LostAfter(10))  # input at 100 Hz: lost from 0.1 s
    loop.run(0.1)
    assert loop.command.vx_mps == 0.3
    loop.run(0.25)
    assert loop.command.vx_mps == 0.0 and not loop.faulted
    loop.run(0.8)
    assert loop.faulted and loop.safety.trip_event.kind == SafetyEventKind.INPUT_LOST
    assert np.all(robot.last_command.kp == 0)


def test_a_robot_that_collapses_after_another_trip_has_fallen():
    """The fall monitor keeps watching once the robot is damped for another reason: the fall is
    recorded, and the trip stays the first cause."""
    loop, robot, _ = _loop()
    loop.run(0.1)
    loop.safety.estop("operator stop", loop.time_s, planned=True)
    robot.pelvis_z_m = 0.3
    loop.run(0.04)
    assert loop.fell and loop.fall.detail == "pelvis at 0.30 m (limit 0.40)"
    assert [e.kind for e in loop.events] == ["estop", "fall"]
    assert loop.safety.trip_event.detail == "operator stop"


def test_a_planned_ending_is_recorded_as_planned():
    loop, _, records = _loop()
    loop.run(0.1)
    loop.safety.estop("operator stop", loop.time_s, planned=True)
    assert loop.events[-1].planned is True and loop.events[-1].trips is True
    assert records[-1]["planned"] is True and records[-1]["kind"] == "estop"


def test_the_feedback_carries_the_state_and_the_localisers_pose():
    loop, robot, _ = _loop(localiser=Localiser(LegOdometry()))
    loop.run(0.1)
    fb = loop.feedback
    # Filled before the last poll (t 0.09 s), which comes before that tick's state read.
    assert fb.t_s == pytest.approx(0.09) and fb.state is robot.states[-2]
    assert fb.pose is not None and fb.pose.t_s == fb.state.t_s, "the localiser's pose of that state"


def test_the_default_safety_filter_carries_the_loops_tilt_limit():
    loop = ControlLoop(StandInRobot(), Still(), VelocityReferenceGenerator(), IKStage(), Hold(), max_tilt_rad=0.7)
    assert loop.safety.config.max_tilt_rad == 0.7 and loop.falls.max_tilt_rad == 0.7
    given = SafetyFilter(SafetyConfig(max_tilt_rad=0.9))
    loop = ControlLoop(StandInRobot(), Still(), VelocityReferenceGenerator(), IKStage(), Hold(), safety=given)
    assert loop.falls.max_tilt_rad == 0.9


class StallingClock:
    """A wall clock for the scheduler that jumps 80 ms once, past 0.2 s (a stalled host)."""

    def __init__(self):
        self.t, self.stalled = 0.0, False

    def __call__(self):
        if not self.stalled and self.t > 0.2:
            self.stalled, self.t = True, self.t + 0.08
        return self.t

    def sleep(self, s):
        self.t += s


def test_a_simulator_paced_by_the_wall_clock_steps_the_ticks_a_stall_skipped():
    """A simulator (lockstep backend) run on the wall clock: one tick stalls 80 ms (the scheduler skips
    the periods it lost). The world went on meanwhile: the simulator steps the skipped ticks too, so the
    state's time stays the loop's and the stale-state check (50 ms) sees no stale state. Before, every
    skipped tick aged the state for good, and a paced sim run (sim_ros2.yaml) damped after ~25 of them."""

    clock = StallingClock()
    loop, robot, _records = _loop(StandInRobot(lockstep=True), wallclock=True,
                                  safety=SafetyFilter(SafetyConfig(stale_state_s=0.05)))
    loop.scheduler.clock, loop.scheduler.sleep = clock, clock.sleep
    loop.run(0.5)
    assert clock.stalled and loop.scheduler.skipped_ticks >= 39  # 80 ms of 2 ms ticks
    assert robot.t_s == pytest.approx(loop.time_s, abs=0.0021), "the simulator kept the loop's time"
    assert not loop.faulted, loop.events


def test_a_wall_clock_simulator_feeds_a_stall_as_the_robot_link_does():
    """The ticks a stall skipped get the last command for its life (safety.command_hold_ticks tracker
    ticks: 3 at 50 Hz, 60 ms of 2 ms ticks), then its hold form (no feedforward torque, no velocity
    target), as hardware/link_backend.py resends it; with the hold off, the command throughout."""

    class Pushing(Hold):
        def act(self, reference, state) -> MotorCommand:
            command = super().act(reference, state)
            command.tau_nm[:] = 1.0
            command.dq_radps[:] = 0.5
            return command

    class Recording(StandInRobot):
        def __init__(self):
            super().__init__(lockstep=True)
            self.written: list[MotorCommand] = []

        def write_command(self, command: MotorCommand) -> None:
            super().write_command(command)
            self.written.append(command)

    for hold_ticks, life in ((3.0, 30), (0.0, None)):
        robot, clock = Recording(), StallingClock()
        loop = ControlLoop(robot, Still(), VelocityReferenceGenerator(), IKStage(), Pushing(), wallclock=True,
                           safety=SafetyFilter(SafetyConfig(command_hold_ticks=hold_ticks)))
        loop.reset()
        loop.scheduler.clock, loop.scheduler.sleep = clock, clock.sleep
        calls: list[list[MotorCommand]] = []

        def spy(n, skipped=loop._skipped_ticks, robot=robot, calls=calls):
            first = len(robot.written)
            skipped(n)
            calls.append(robot.written[first:])

        loop.scheduler.on_skip = spy
        loop.run(0.3)
        assert len(calls) == 1 and len(calls[0]) >= 39, [len(c) for c in calls]
        fed = calls[0]
        pushing = [c.tau_nm.any() or c.dq_radps.any() for c in fed]
        if life is None:
            assert all(pushing)
        else:
            assert pushing == [True] * life + [False] * (len(fed) - life)
            np.testing.assert_array_equal(fed[-1].q_rad, fed[0].q_rad)
            np.testing.assert_array_equal(fed[-1].kp, fed[0].kp)
