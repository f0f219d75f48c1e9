"""The loop itself: bad commands never reach the tracker, upper-body override, wall-clock pacing."""

import time

import numpy as np
import pytest

from g1_control.generator.velocity import VelocityReferenceGenerator
from g1_control.ik.stage import IKStage
from g1_control.interfaces import Generator, InputDevice
from g1_control.loop.control_loop import ControlLoop
from g1_control.robot import g1
from g1_control.sim.mujoco_backend import MujocoBackend
from g1_control.trackers.locomotion import LocomotionPolicyTracker
from g1_control.trackers.policy_spec import load_spec
from g1_control.types import PHASE_LOCOMOTION, PHASE_WHOLE_BODY, Command, JointReference, KinematicReference


class SequenceInput(InputDevice):
    def __init__(self, commands):
        self.commands = iter(commands)
        self.last = Command()

    def poll(self, now_s):
        self.last = next(self.commands, self.last)
        return self.last


def make_loop(device, generator=None, **kw):
    tracker = LocomotionPolicyTracker(load_spec("holosoma_loco_ppo"))
    loop = ControlLoop(MujocoBackend(), device, generator or VelocityReferenceGenerator(), IKStage(),
                       tracker, log_capacity=1000, **kw)
    loop.reset()
    return loop


def test_nan_command_is_dropped_then_stops_then_damps():
    good = Command(vx_mps=0.3)
    device = SequenceInput([Command()] * 50 + [good] * 50 + [Command(vx_mps=float("nan"))] * 500)
    loop = make_loop(device)
    loop.run(1.1)  # NaN since 1.0 s: the last good command stays in force for a moment
    assert loop.invalid_commands > 0 and loop.command.vx_mps == 0.3
    assert loop.events[0].kind == "invalid_command" and "vx_mps is nan" in loop.events[0].detail
    loop.run(0.4)  # late input: velocity zeroed, robot still controlled
    assert loop.command.vx_mps == 0.0 and not loop.faulted
    assert np.all(np.isfinite(loop.log.arrays()["q_target_rad"]))
    loop.run(0.7)  # over a second without valid input: damping for good
    assert loop.faulted and loop.safety.trip_event.kind.value == "input_lost"
    assert np.all(loop.motor_command.kp == 0) and np.all(loop.motor_command.kd > 0)


def test_estop_button_damps_at_once():
    device = SequenceInput([Command(vx_mps=0.2)] * 20 + [Command(buttons=frozenset({"estop"}))])
    loop = make_loop(device)
    loop.run(0.3)
    assert loop.faulted and loop.safety.trip_event.kind.value == "estop"
    assert abs(loop.safety.trip_event.t_s - 0.2) < 0.011
    assert np.all(loop.motor_command.kp == 0)


class WavingArms(Generator):
    """Stand still while both shoulders swing +-0.4 rad at 0.5 Hz: a feasible plan that asks for
    the upper body."""

    def __init__(self):
        self.plan = JointReference(q_rad=g1.DEFAULT_Q_RAD.copy(), upper_body_override=True)
        self.ref = KinematicReference(q_rad=self.plan.q_rad, feasible_plan=self.plan)

    def update(self, command, state):
        wave = 0.4 * np.sin(2 * np.pi * 0.5 * state.t_s)
        for name in ("left_shoulder_pitch_joint", "right_shoulder_pitch_joint"):
            self.plan.q_rad[g1.JOINT_INDEX[name]] = g1.DEFAULT_Q_RAD[g1.JOINT_INDEX[name]] + wave
        return self.ref


def test_upper_body_override_moves_the_arms_while_the_policy_balances():
    tracker = LocomotionPolicyTracker(load_spec("holosoma_loco_ppo"))
    loop = ControlLoop(MujocoBackend(), SequenceInput([]), WavingArms(), IKStage(), tracker,
                       log_capacity=400)
    loop.reset()
    loop.run(6.0)
    log = loop.log.arrays()
    j = g1.JOINT_INDEX["left_shoulder_pitch_joint"]
    swing = log["q_rad"][100:, j]
    assert not loop.fell
    assert swing.max() - swing.min() > 0.6  # the arm really swings (target amplitude 0.8 peak to peak)
    expected = g1.DEFAULT_Q_RAD[j] + 0.4 * np.sin(2 * np.pi * 0.5 * log["t_s"][100:])
    target_rms = np.sqrt(np.mean((log["q_target_rad"][100:, j] - expected) ** 2))
    tracking_rms = np.sqrt(np.mean((swing - expected) ** 2))
    assert target_rms < 0.05 and tracking_rms < 0.2


@pytest.mark.timing  # paced by the wall clock: a loaded host skips ticks (mutmut's clean run did: 265 ticks)
def test_wallclock_mode_runs_in_real_time():
    loop = make_loop(SequenceInput([]), wallclock=True)
    t0 = time.perf_counter()
    loop.run(0.5)
    elapsed = time.perf_counter() - t0
    assert elapsed >= 0.49  # paced: never faster than real time
    assert loop.scheduler.tick_index == 250


@pytest.mark.parametrize("policy", ["holosoma_loco_fastsac"])
def test_other_builtin_policy_walks(policy):
    device = SequenceInput([Command()] * 100 + [Command(vx_mps=0.4)] * 500)
    tracker = LocomotionPolicyTracker(load_spec(policy))
    loop = ControlLoop(MujocoBackend(), device, VelocityReferenceGenerator(), IKStage(), tracker,
                       log_capacity=400)
    loop.reset()
    loop.run(6.0)
    log = loop.log.arrays()
    assert not loop.fell
    assert log["velocity_true"][-100:, 0].mean() > 0.3


class GoalReportingGenerator(VelocityReferenceGenerator):
    """Reports one goal reached and the whole-body phase from 0.3 s on (as a goal executor would)."""

    def __init__(self):
        super().__init__()
        self.goal_status: dict[str, str] = {}
        self.goal_messages = {"g0": "out of reach"}

    def update(self, command, state):
        if state.t_s >= 0.3:
            self.goal_status["g1"] = "reached"
            self.phase = PHASE_WHOLE_BODY
        return super().update(command, state)


class FeedbackRecorder(SequenceInput):
    def __init__(self):
        super().__init__([])
        self.seen = []
        self.loop = None

    def observe(self, feedback):
        self.feedback = feedback
        self.seen.append((feedback.t_s, feedback.phase, dict(feedback.goal_status), feedback.truth is not None))
        if self.loop is not None:  # the loop's own latest state and estimate, not copies
            assert feedback.truth is self.loop.state and feedback.estimate is self.loop.estimator.estimate

    def poll(self, now_s):
        assert self.seen[-1][0] == now_s, "the record is filled for this poll, before it"
        return super().poll(now_s)


def test_the_loop_feeds_one_record_back_to_the_input_before_every_poll():
    device = FeedbackRecorder()
    generator = GoalReportingGenerator()
    loop = make_loop(device, generator)
    device.loop = loop
    loop.run(0.5)
    fb = loop.feedback
    assert device.feedback is fb and len(device.seen) == 50, "one record, given before each of the 50 polls (100 Hz)"
    assert fb.goal_status is generator.goal_status and fb.goal_messages["g0"] == "out of reach"
    early = [s for s in device.seen if s[0] < 0.25]
    late = [s for s in device.seen if s[0] > 0.35]
    assert all(p == PHASE_LOCOMOTION and g == {} for _, p, g, _ in early)
    assert all(p == PHASE_WHOLE_BODY and g == {"g1": "reached"} for _, p, g, _ in late)
    assert all(truth for *_, truth in device.seen), "MuJoCo gives ground truth"


def test_a_generator_without_goals_reports_none_and_a_robot_gives_no_truth():
    device = FeedbackRecorder()
    loop = make_loop(device)
    loop.state.base_pos_w_m = None  # what a robot's state looks like
    loop._feed_back(0.0)
    fb = device.feedback
    assert fb.truth is None and fb.phase == PHASE_LOCOMOTION and dict(fb.goal_status) == {}
    with pytest.raises(TypeError):
        fb.goal_status["g1"] = "reached"  # the shared empty table is read-only
