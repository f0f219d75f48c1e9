"""The deploy state machine (DeployTracker) on a fake clock: order of states, the ramp, operator
buttons from the real Unitree remote decoder and mapping, and damping on every way out."""

from __future__ import annotations

import numpy as np
import pytest

from g1_control.deploy.state_machine import DeployState, DeployTracker, OperatorButtons, smooth_step
from g1_control.interfaces import InputDevice, Tracker
from g1_control.launch.schema import DeployConfig
from g1_control.robot import g1
from g1_control.safety import SafetyEventKind, SafetyFilter
from g1_control.teleop.unitree_remote import UnitreeRemote, encode_wireless_remote
from g1_control.types import Command, ExecutionFeedback, JointReference, MotorCommand, RobotState


class Clock:
    def __init__(self):
        self.t = 100.0

    def __call__(self) -> float:
        return self.t


class PolicyStub(Tracker):
    """Stands in for the ONNX policy: marks its commands so the test can tell whose they are."""

    def __init__(self):
        self.resets = 0

    def act(self, reference, state) -> MotorCommand:
        return MotorCommand(q_rad=np.full(g1.NUM_JOINTS, 0.123), kp=np.full(g1.NUM_JOINTS, 50.0),
                            kd=np.ones(g1.NUM_JOINTS))

    def reset(self, state=None) -> None:
        self.resets += 1


class Buttons(InputDevice):
    def __init__(self):
        self.next: frozenset[str] = frozenset()

    def poll(self, now_s: float) -> Command:
        buttons, self.next = self.next, frozenset()
        return Command(buttons=buttons)


def _machine(auto=False, control_s=None, ramp_s=2.0):
    clock, safety, policy, device = Clock(), SafetyFilter(), PolicyStub(), Buttons()
    buttons = OperatorButtons(device)
    tracker = DeployTracker(policy, g1.DEFAULT_Q_RAD, g1.KP_DEFAULT, g1.KD_DEFAULT, safety, clock,
                            DeployConfig(ramp_s=ramp_s, auto_start_s=0.5, auto_run_s=1.0), buttons=buttons, auto=auto,
                            control_s=control_s)
    return tracker, clock, safety, policy, device, buttons


def _state(q=None) -> RobotState:
    return RobotState(q_rad=np.zeros(g1.NUM_JOINTS) if q is None else q)


def _press(device, buttons, *names):
    device.next = frozenset(names)
    buttons.poll(0.0)


def _act(tracker, clock, dt=0.02, state=None):
    clock.t += dt
    return tracker.act(JointReference(), state or _state())


def test_operator_sequence_zero_torque_ramp_hold_control_then_stop_damps():
    tracker, clock, safety, policy, device, buttons = _machine()
    cmd = _act(tracker, clock)
    assert tracker.state == DeployState.ZERO_TORQUE
    assert np.all(cmd.kp == 0) and np.all(cmd.kd == 0) and np.all(cmd.tau_nm == 0), "zero torque: limp"
    for _ in range(50):  # nothing happens without the operator
        _act(tracker, clock)
    assert tracker.state == DeployState.ZERO_TORQUE

    _press(device, buttons, "start")
    cmd = _act(tracker, clock)
    assert tracker.state == DeployState.RAMP
    np.testing.assert_allclose(cmd.kp, g1.KP_DEFAULT)
    # Ramp from where the joints are (zeros) to the default pose, smoothly, over ramp_s.
    targets = [_act(tracker, clock).q_rad.copy() for _ in range(99)]  # 2.0 s at 50 Hz, minus the first tick
    assert tracker.state == DeployState.RAMP
    knee = g1.JOINT_INDEX["left_knee_joint"]
    knee_path = np.array([t[knee] for t in targets])
    assert np.all(np.diff(knee_path) >= -1e-12) and knee_path[0] < 0.01 * g1.DEFAULT_Q_RAD[knee]
    assert knee_path[-1] == pytest.approx(g1.DEFAULT_Q_RAD[knee], abs=1e-3)
    for _ in range(2):  # 100 ticks of 0.02 s may sum to a hair under 2 s
        cmd = _act(tracker, clock)
    assert tracker.state == DeployState.HOLD
    ramp, hold = tracker.transitions[0].t_s, tracker.transitions[1].t_s
    assert 2.0 <= hold - ramp <= 2.05, "the ramp takes ramp_s (>= 2 s), no less"
    np.testing.assert_allclose(cmd.q_rad, g1.DEFAULT_Q_RAD)

    _press(device, buttons, "run")  # pressed at once: waits until the pose was held min_hold_s
    cmd = _act(tracker, clock)
    assert tracker.state == DeployState.HOLD
    hold_ticks = 1
    while tracker.state == DeployState.HOLD and hold_ticks < 100:
        cmd = _act(tracker, clock)
        hold_ticks += 1
    assert tracker.state == DeployState.CONTROL and policy.resets == 1
    assert tracker.transitions[-1].t_s - tracker.transitions[-2].t_s == pytest.approx(0.5, abs=0.021)
    assert tracker.transitions[-1].reason == "operator run"
    assert np.all(cmd.q_rad == 0.123), "the policy's command goes out in control"
    assert tracker.control_elapsed_s() == 0.0
    _act(tracker, clock, dt=1.0)
    assert tracker.control_elapsed_s() == pytest.approx(1.0)

    _press(device, buttons, "stop")
    cmd = _act(tracker, clock)
    assert tracker.state == DeployState.DAMPING
    assert safety.tripped and safety.trip_event.kind == SafetyEventKind.ESTOP
    assert safety.trip_event.detail == "operator stop"
    assert np.all(cmd.kp == 0) and np.all(cmd.kd > 0), "damping: kp 0, kd > 0"
    _press(device, buttons, "start")
    _press(device, buttons, "run")
    assert np.all(_act(tracker, clock).kp == 0), "damping is for good"
    assert tracker.sequence == ["zero_torque", "ramp", "hold", "control", "damping"]


def test_run_is_ignored_before_start_and_during_the_ramp():
    tracker, clock, _, _, device, buttons = _machine()
    _press(device, buttons, "run")
    _act(tracker, clock)
    assert tracker.state == DeployState.ZERO_TORQUE
    _press(device, buttons, "start")
    _act(tracker, clock)
    _press(device, buttons, "run")
    _act(tracker, clock)
    assert tracker.state == DeployState.RAMP
    assert tracker.ignored == ["run ignored in zero_torque: press start first",
                               "run ignored during the ramp: wait for hold"]


def test_a_press_between_tracker_ticks_is_not_lost():
    tracker, clock, _, _, device, buttons = _machine()
    _press(device, buttons, "start")
    buttons.poll(0.0)  # a second input poll in the same tracker tick, with nothing pressed
    _act(tracker, clock)
    assert tracker.state == DeployState.RAMP


def test_yes_answers_start_and_run_and_the_control_time_ends_in_damping():
    tracker, clock, safety, _, _, _ = _machine(auto=True, control_s=3.0)
    t0 = clock.t
    while tracker.state != DeployState.DAMPING and clock.t - t0 < 20:
        _act(tracker, clock)
    times = {t.target: t.t_s - t0 for t in tracker.transitions}
    assert times[DeployState.RAMP] == pytest.approx(0.52, abs=0.03)
    assert times[DeployState.HOLD] - times[DeployState.RAMP] == pytest.approx(2.0, abs=0.03)
    assert times[DeployState.CONTROL] - times[DeployState.HOLD] == pytest.approx(1.0, abs=0.03)
    assert times[DeployState.DAMPING] - times[DeployState.CONTROL] == pytest.approx(3.0, abs=0.03)
    assert safety.trip_event.detail.startswith("control time over")


@pytest.mark.parametrize("state_before", [DeployState.RAMP, DeployState.CONTROL])
def test_a_safety_trip_in_any_state_ends_in_damping(state_before):
    tracker, clock, safety, _, device, buttons = _machine()
    _press(device, buttons, "start")
    _act(tracker, clock)
    if state_before == DeployState.CONTROL:
        for _ in range(120):
            _act(tracker, clock)
        _press(device, buttons, "run")
        for _ in range(30):
            _act(tracker, clock)
    assert tracker.state == state_before
    tilted = _state()
    tilted.t_s = clock.t
    tilted.imu_quat_wxyz = np.array([np.cos(0.7), np.sin(0.7), 0.0, 0.0])  # 1.4 rad
    safety.check(tilted, clock.t)
    cmd = _act(tracker, clock)
    assert tracker.state == DeployState.DAMPING
    assert tracker.transitions[-1].reason.startswith("tilt: pelvis tilted 1.40 rad")
    assert np.all(cmd.kp == 0) and np.all(cmd.kd > 0)


def test_ramp_profile_is_smooth_at_both_ends():
    assert smooth_step(0.0) == 0.0 and smooth_step(1.0) == 1.0 and smooth_step(2.0) == 1.0
    eps = 1e-4
    assert smooth_step(eps) / eps < 1e-3 and (1 - smooth_step(1 - eps)) / eps < 1e-3


def test_unitree_remote_buttons_drive_the_machine():
    """start / A / B and L1+R1 as the robot reports them in LowState.wireless_remote."""
    clock = Clock()
    samples: list[bytes] = [encode_wireless_remote()]

    def source():
        return samples[-1]

    remote = UnitreeRemote(state_source=source, clock=clock)
    buttons = OperatorButtons(remote)
    safety = SafetyFilter()
    tracker = DeployTracker(PolicyStub(), g1.DEFAULT_Q_RAD, g1.KP_DEFAULT, g1.KD_DEFAULT, safety, clock,
                            DeployConfig(ramp_s=2.0), buttons=buttons)

    def tick(*held):
        samples.append(encode_wireless_remote(held))
        clock.t += 0.02
        command = buttons.poll(clock.t)
        safety.vet_input(command, clock.t)
        tracker.act(JointReference(), _state())

    tick()
    tick("start")
    assert tracker.state == DeployState.RAMP
    for _ in range(101):
        tick()
    assert tracker.state == DeployState.HOLD
    tick("A")
    for _ in range(25):  # min_hold_s 0.5 s
        tick()
    assert tracker.state == DeployState.CONTROL
    tick()
    tick("L1", "R1")  # e-stop chord
    tick()
    assert tracker.state == DeployState.DAMPING
    assert safety.trip_event.detail == "e-stop pressed on the operator input"


def test_a_trip_the_loop_handled_alone_is_observed_without_act():
    """After a trip the control loop stops calling the tracker; its driver still sees the damping."""
    tracker, clock, safety, _, _, _ = _machine()
    _act(tracker, clock)
    safety.estop("e-stop pressed on the operator input", clock.t)
    assert tracker.observe_safety(clock.t + 0.01)
    assert tracker.state == DeployState.DAMPING
    assert tracker.transitions[-1].reason == "estop: e-stop pressed on the operator input"


def test_operator_buttons_pass_the_loops_feedback_to_the_device_inside():
    class Steering(Buttons):
        def observe(self, feedback):
            self.feedback = feedback

    device = Steering()
    feedback = ExecutionFeedback(phase="whole_body")
    OperatorButtons(device).observe(feedback)
    assert device.feedback is feedback
