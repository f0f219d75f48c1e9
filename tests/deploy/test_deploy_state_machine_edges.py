"""The deploy state machine at its exact limits and in its words (issue 26: the mutation run's loop
group): every transition at the first tick its time allows (ticks of 0.25 s on a fake clock, exact
in binary), the reasons and times the report and the operator read, the planned flag of the
machine's own endings, the ramp's path from where the joints are, the gains it holds the pose with,
what the wrapped policy is given, and the input device's clock."""

from __future__ import annotations

import logging

import numpy as np
import pytest
from test_deploy_state_machine import Clock  # a settable clock at 100 s

from g1_control.deploy.state_machine import DeployState, DeployTracker, OperatorButtons, Transition, smooth_step
from g1_control.interfaces import InputDevice, Tracker
from g1_control.launch.schema import DeployConfig
from g1_control.robot import g1
from g1_control.safety import SafetyEventKind, SafetyFilter
from g1_control.teleop.scripted import ScriptedInput, Segment
from g1_control.types import Command, JointReference, MotorCommand, RobotState

DT = 0.25  # exact in binary: in_state lands exactly on every limit below


class RecordingPolicy(Tracker):
    """Stands in for the ONNX policy: records what it is given."""

    def __init__(self):
        self.reset_states: list[RobotState | None] = []
        self.acted: list[tuple[JointReference, RobotState]] = []

    def act(self, reference, state) -> MotorCommand:
        self.acted.append((reference, state))
        return MotorCommand(q_rad=np.full(g1.NUM_JOINTS, 0.123), kp=np.full(g1.NUM_JOINTS, 50.0),
                            kd=np.ones(g1.NUM_JOINTS))

    def reset(self, state=None) -> None:
        self.reset_states.append(state)


class Buttons(InputDevice):
    def __init__(self):
        self.next: frozenset[str] = frozenset()
        self.polled_at: list[float] = []

    def poll(self, now_s: float) -> Command:
        self.polled_at.append(now_s)
        buttons, self.next = self.next, frozenset()
        return Command(buttons=buttons)


CONFIG = DeployConfig(ramp_s=2.0, min_hold_s=0.5, auto_start_s=0.5, auto_run_s=1.0)


def _machine(*, auto=False, control_s=None, buttons=True, default_q=None, **kw):
    clock, safety, policy, device = Clock(), SafetyFilter(), RecordingPolicy(), Buttons()
    ops = OperatorButtons(device) if buttons else None
    tracker = DeployTracker(policy, g1.DEFAULT_Q_RAD if default_q is None else default_q, g1.KP_DEFAULT,
                            g1.KD_DEFAULT, safety, clock, CONFIG, buttons=ops, auto=auto, control_s=control_s, **kw)
    return tracker, clock, safety, policy, device, ops


def _state(q=None) -> RobotState:
    return RobotState(q_rad=np.zeros(g1.NUM_JOINTS) if q is None else np.asarray(q, float))


def _press(device, ops, *names):
    device.next = frozenset(names)
    ops.poll(0.0)


def _act(tracker, clock, state=None):
    clock.t += DT
    return tracker.act(JointReference(), state or _state())


def _ticks_until(tracker, clock, target, limit=40):
    """Ticks (of DT) until the machine is in `target`."""
    for n in range(1, limit + 1):
        _act(tracker, clock)
        if tracker.state == target:
            return n
    raise AssertionError(f"never reached {target}: {tracker.sequence}")


def _start_then_run(tracker, clock, device, ops):
    """One tick limp, the operator's start, ticks until the hold, then run pressed (not yet ticked)."""
    _act(tracker, clock)
    _press(device, ops, "start")
    _ticks_until(tracker, clock, DeployState.HOLD)
    _press(device, ops, "run")


def test_auto_start_run_and_control_time_each_at_the_first_tick_their_time_allows():
    tracker, clock, safety, _, _, _ = _machine(auto=True, control_s=1.5)
    # The first tick starts the clock of zero_torque; auto_start_s 0.5 = 2 ticks later.
    assert _ticks_until(tracker, clock, DeployState.RAMP) == 3
    assert _ticks_until(tracker, clock, DeployState.HOLD) == 8, "ramp_s 2.0: 8 ticks"
    assert _ticks_until(tracker, clock, DeployState.CONTROL) == 4, "auto_run_s 1.0: 4 ticks"
    assert _ticks_until(tracker, clock, DeployState.DAMPING) == 6, "control_s 1.5: 6 ticks"
    assert [str(t) for t in tracker.transitions] == [
        "zero_torque -> ramp: start (--yes)", "ramp -> hold: default pose reached (2.0 s ramp)",
        "hold -> control: run (--yes)", "control -> damping: control time over (1.5 s)"]
    assert [t.t_s - 100.0 for t in tracker.transitions] == [0.75, 2.75, 3.75, 5.25]
    trip = safety.trip_event
    assert trip.kind == SafetyEventKind.ESTOP and trip.planned is True
    assert trip.detail == "control time over (1.5 s, launch duration_s)" and trip.t_s == 105.25


def test_a_run_pressed_early_is_taken_at_exactly_min_hold():
    tracker, clock, _, _policy, device, ops = _machine()
    _start_then_run(tracker, clock, device, ops)
    assert _ticks_until(tracker, clock, DeployState.CONTROL) == 2, "min_hold_s 0.5: 2 ticks"
    assert tracker.transitions[-1].reason == "operator run"
    assert tracker.transitions[0].reason == "operator start"


def test_without_auto_nothing_starts_on_its_own():
    clock, safety = Clock(), SafetyFilter()
    tracker = DeployTracker(RecordingPolicy(), g1.DEFAULT_Q_RAD, g1.KP_DEFAULT, g1.KD_DEFAULT, safety, clock, CONFIG)
    for _ in range(20):  # 5 s, ten times auto_start_s
        _act(tracker, clock)
    assert tracker.state == DeployState.ZERO_TORQUE and tracker.transitions == []


def test_operator_stop_is_a_planned_estop_at_its_time_in_words():
    seen: list[Transition] = []
    tracker, clock, safety, _, device, ops = _machine(on_transition=seen.append)
    _act(tracker, clock)
    _press(device, ops, "start")
    _act(tracker, clock)
    _press(device, ops, "stop")
    cmd = _act(tracker, clock)
    assert tracker.state == DeployState.DAMPING and np.all(cmd.kp == 0)
    stop = tracker.transitions[-1]
    assert (stop.source, stop.target, stop.reason, stop.t_s) == (DeployState.RAMP, DeployState.DAMPING,
                                                                "operator stop", 100.75)
    assert safety.trip_event.detail == "operator stop" and safety.trip_event.planned is True
    assert safety.trip_event.t_s == 100.75
    assert seen == tracker.transitions, "every transition reaches on_transition, as it is recorded"


def test_a_safety_trip_is_entered_at_the_tick_that_sees_it():
    tracker, clock, safety, _, _, _ = _machine()
    _act(tracker, clock)
    safety.estop("e-stop pressed on the operator input", clock.t)
    _act(tracker, clock)
    trip = tracker.transitions[-1]
    assert (trip.source, trip.target, trip.t_s) == (DeployState.ZERO_TORQUE, DeployState.DAMPING, 100.5)
    assert tracker.observe_safety(101.0) and tracker.transitions[-1] is trip, "damping is entered once"


def test_transitions_are_logged_at_info_for_the_operator(caplog):
    tracker, clock, _, _, device, ops = _machine()
    with caplog.at_level(logging.INFO, logger="g1_control.deploy"):
        _act(tracker, clock)
        _press(device, ops, "start")
        _act(tracker, clock)
    assert [r.getMessage() for r in caplog.records] == ["deploy: zero_torque -> ramp: operator start"]
    assert caplog.records[0].levelno == logging.INFO


def test_the_ramp_runs_from_where_the_joints_are_to_the_default_pose_over_ramp_s():
    tracker, clock, _, _, device, ops = _machine()
    start_q = g1.DEFAULT_Q_RAD + 0.3
    _act(tracker, clock, _state(start_q))
    _press(device, ops, "start")
    first = _act(tracker, clock, _state(start_q)).q_rad.copy()
    np.testing.assert_allclose(first, start_q, err_msg="the ramp starts where the joints are")
    for _ in range(3):
        _act(tracker, clock)
    half = _act(tracker, clock).q_rad  # 1.0 s of the 2.0 s ramp: half way
    assert smooth_step(0.5) == pytest.approx(0.5)
    np.testing.assert_allclose(half, start_q + 0.5 * (g1.DEFAULT_Q_RAD - start_q), atol=1e-12)


def test_ramp_and_hold_command_the_policy_gains_and_the_default_pose():
    tracker, clock, _, _, device, ops = _machine()
    zero = _act(tracker, clock)
    assert zero.is_finite() and np.all(zero.q_rad == 0) and np.all(zero.kd == 0)
    _press(device, ops, "start")
    ramp = _act(tracker, clock)
    np.testing.assert_array_equal(ramp.kp, g1.KP_DEFAULT)
    np.testing.assert_array_equal(ramp.kd, g1.KD_DEFAULT)
    _ticks_until(tracker, clock, DeployState.HOLD)
    hold = _act(tracker, clock)
    np.testing.assert_array_equal(hold.q_rad, g1.DEFAULT_Q_RAD)
    np.testing.assert_array_equal(hold.kd, g1.KD_DEFAULT)


def test_a_default_pose_given_as_integers_still_ramps_smoothly():
    """A pose typed as whole numbers (YAML `0`, `1`) must not make an integer pose that truncates the ramp."""
    default = [1] * g1.NUM_JOINTS
    tracker, clock, _, _, device, ops = _machine(default_q=default)
    _act(tracker, clock)
    _press(device, ops, "start")
    for _ in range(4):
        _act(tracker, clock)
    half = _act(tracker, clock).q_rad  # 1.0 s of the 2.0 s ramp from 0 to 1
    np.testing.assert_allclose(half, 0.5, atol=1e-12)


def test_control_hands_the_policy_the_reference_and_state_and_resets_it_with_the_state():
    tracker, clock, _, policy, device, ops = _machine()
    _start_then_run(tracker, clock, device, ops)
    _act(tracker, clock)
    state, reference = _state(g1.DEFAULT_Q_RAD), JointReference()
    clock.t += DT
    cmd = tracker.act(reference, state)
    assert tracker.state == DeployState.CONTROL and np.all(cmd.q_rad == 0.123)
    assert policy.reset_states == [state], "the policy starts from the state at the run"
    assert policy.acted == [(reference, state)]


def test_clocks_read_zero_before_their_start():
    tracker, clock, _, _, _, _ = _machine()
    assert tracker.time_in_state_s(clock.t + 5.0) == 0.0, "before the machine's first tick"
    assert tracker.control_elapsed_s() == 0.0, "before control"
    _act(tracker, clock)
    assert tracker.time_in_state_s(clock.t + 0.5) == 0.5
    assert tracker.control_elapsed_s() == 0.0


def test_a_machine_without_buttons_runs_on_auto():
    tracker, clock, _, _, _, _ = _machine(auto=True, buttons=False)
    assert _ticks_until(tracker, clock, DeployState.CONTROL, limit=20) == 15


def test_presses_on_two_polls_within_one_tick_are_both_kept():
    tracker, clock, _, _, device, ops = _machine()
    _act(tracker, clock)
    _press(device, ops, "start")
    _press(device, ops, "stop")
    assert ops.take() == {"start", "stop"}


def test_a_live_device_is_polled_on_the_loops_clock_even_with_a_timeline_clock():
    device = Buttons()
    ops = OperatorButtons(device)
    ops.timeline_clock = lambda: 7.0
    ops.poll(3.0)
    assert device.polled_at == [3.0]


def test_a_scripted_timeline_plays_on_the_control_clock_once_given_one():
    timeline = ScriptedInput([Segment(duration_s=1.0, vx_mps=0.3), Segment(duration_s=1.0, vx_mps=0.6)])
    ops = OperatorButtons(timeline)
    assert ops.poll(1.5).vx_mps == 0.6, "no control clock yet: the loop's time"
    ops.timeline_clock = lambda: 0.5
    assert ops.poll(1.5).vx_mps == 0.3, "the control clock: 0.5 s into the timeline"


def test_the_operators_button_chords_are_the_devices_own():
    """What the loop's input says stops or starts the robot is what the device binds (a prompt or the
    preflight asking the wrapped device gets the device's chords, per action)."""

    class Bound(Buttons):
        def button_chords(self, action: str) -> list[str]:
            return {"estop": ["L1+R1"], "stop": ["B"]}.get(action, [])

    ops = OperatorButtons(Bound())
    assert ops.button_chords("estop") == ["L1+R1"] and ops.button_chords("stop") == ["B"]
    assert ops.button_chords("start") == []
