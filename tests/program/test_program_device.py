"""ProgramInput (a program as the loop's input) and the ground-truth judge, against a stand-in loop
whose estimator and simulator state come from integrating the commands exactly (kinematic)."""

import math

import numpy as np
import pytest

from g1_control.interfaces import InputDevice
from g1_control.program import COMPLETED, Landmark, Program, World, parse_instruction
from g1_control.program.device import Odometry, PlanarPose, ProgramInput, StepRecord, record_dict
from g1_control.program.judge import judge
from g1_control.program.runner import StepOutcome
from g1_control.program.steps import Height, Stand, Turn, Walk
from g1_control.types import Command, EstimatedState, ExecutionFeedback, RobotState


def yaw_quat(yaw):
    return np.array([math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2)])


class FakeLoop:
    """Moves exactly as commanded (heading-frame velocity, yaw rate). The estimator's velocity
    is the true one times `odometry_scale` (a leg odometry that under-reads), so the runner's
    pose and ground truth differ in a known way. Like the ControlLoop, it feeds back through one
    ExecutionFeedback record, filled in place (tests set its goal_status and phase directly)."""

    def __init__(self, odometry_scale=1.0):
        self.x = self.y = self.yaw = 0.0
        self.t = 0.0
        self.scale = odometry_scale
        self.feedback = ExecutionFeedback(estimate=EstimatedState(), goal_status={})
        self._publish(np.zeros(3))

    def connect(self, device):
        device.observe(self.feedback)

    def _publish(self, v_w):
        est = self.feedback.estimate
        est.t_s, est.yaw_rad = self.t, self.yaw
        est.base_linvel_w_mps = v_w * self.scale
        est.pelvis_height_m = 0.75
        self.feedback.t_s = self.t
        self.feedback.truth = RobotState(t_s=self.t, imu_quat_wxyz=yaw_quat(self.yaw),
                                         base_pos_w_m=np.array([self.x, self.y, 0.75]))

    def step(self, cmd: Command, dt=0.01):
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        v_w = np.array([c * cmd.vx_mps - s * cmd.vy_mps, s * cmd.vx_mps + c * cmd.vy_mps, 0.0])
        self.x += v_w[0] * dt
        self.y += v_w[1] * dt
        self.yaw = math.remainder(self.yaw + cmd.wz_radps * dt, math.tau)
        self.t += dt
        self._publish(v_w)


def drive(device, loop, max_s=120.0, dt=0.01):
    loop.connect(device)
    while not device.done and loop.t < max_s:
        loop.step(device.poll(loop.t), dt)
    return device


def test_program_runs_on_odometry_and_is_judged_from_ground_truth():
    loop = FakeLoop()
    device = drive(ProgramInput(parse_instruction("walk forward 2 meters, then turn left 90 degrees"), start_delay_s=0.5),
                   loop)
    walk, turn = device.records
    assert walk.outcome.status == turn.outcome.status == COMPLETED
    assert walk.outcome.started_s >= 0.5, "stands for start_delay_s first"
    assert walk.truth_start.x_m == pytest.approx(0.0, abs=1e-9)
    assert walk.truth_end.x_m == pytest.approx(2.0, abs=0.03)
    assert walk.verdict.ok and abs(walk.verdict.values["error_rel"]) < 0.02
    assert turn.truth_turned_rad == pytest.approx(math.pi / 2, abs=math.radians(2))
    assert turn.verdict.ok
    assert device.ended_s is not None and device.done


def test_odometry_that_under_reads_walks_too_far_and_the_judge_says_so():
    """The runner steers by odometry reading 80 % of the true speed: it walks 2 m by its own
    account, 2.5 m in truth; the ground-truth verdict misses (+25 %), the runner's does not."""
    loop = FakeLoop(odometry_scale=0.8)
    device = drive(ProgramInput(parse_instruction("walk forward 2 meters"), start_delay_s=0.0), loop)
    (walk,) = device.records
    assert walk.outcome.status == COMPLETED
    assert walk.outcome.measured["distance_m"] == pytest.approx(2.0, abs=0.03)
    assert walk.truth_end.x_m == pytest.approx(2.5, abs=0.05)
    assert not walk.verdict.ok and walk.verdict.values["error_rel"] == pytest.approx(0.25, abs=0.03)


def test_ground_truth_pose_source_steers_by_the_simulator():
    loop = FakeLoop(odometry_scale=0.8)
    device = drive(ProgramInput(parse_instruction("walk forward 2 meters"), pose="ground_truth", start_delay_s=0.0),
                   loop)
    assert device.records[0].verdict.ok
    assert loop.x == pytest.approx(2.0, abs=0.03)


def test_a_full_circle_is_judged_by_the_yaw_turned_tick_by_tick():
    loop = FakeLoop()
    device = drive(ProgramInput(parse_instruction("spin right 360 degrees"), start_delay_s=0.0), loop)
    (turn,) = device.records
    assert turn.truth_turned_rad == pytest.approx(-2 * math.pi, abs=math.radians(2))
    assert turn.verdict.ok
    assert abs(turn.truth_end.yaw_rad - turn.truth_start.yaw_rad) < math.radians(3), "start and end look alike"


def test_walk_to_a_place_and_back_to_the_start():
    world = World.of(Landmark("door", np.array([2.0, 1.0, 0.0]), "point"))
    loop = FakeLoop()
    device = drive(ProgramInput(parse_instruction("walk to the door, then go back to the start", places=world.names()),
                                world, start_delay_s=0.0), loop)
    to_door, back = device.records
    assert to_door.verdict.ok and back.verdict.ok
    assert math.hypot(loop.x, loop.y) < 0.06


def test_start_delay_holds_and_the_program_clock_replaces_the_loop_clock():
    loop = FakeLoop()
    device = ProgramInput(parse_instruction("walk forward 1 meter"), start_delay_s=1.0)
    loop.connect(device)
    clock = [0.0]
    device.program_clock = lambda: clock[0]
    for k in range(300):  # 3 s of loop time with the program clock stopped (deploy: before control)
        cmd = device.poll(k * 0.01)
        assert cmd.vx_mps == 0.0
    clock[0] = 1.5
    assert device.poll(3.0).vx_mps > 0.0


def test_operator_buttons_and_loss_pass_through():
    class Operator(InputDevice):
        lost = False

        def poll(self, now_s):
            return Command(vx_mps=0.7, buttons=frozenset({"estop"}))

        def observe(self, feedback):
            self.feedback = feedback

        def close(self):
            self.closed = True

    op = Operator()
    loop = FakeLoop()
    device = ProgramInput(parse_instruction("wait 2 seconds"), operator=op, start_delay_s=0.0)
    loop.connect(device)
    assert op.feedback is loop.feedback, "the operator's device gets the loop's feedback too"
    cmd = device.poll(0.0)
    assert cmd.buttons == frozenset({"estop"}) and cmd.vx_mps == 0.0, "motion from the program, buttons from the operator"
    op.lost = True
    assert device.lost
    device.close()
    assert op.closed


def test_goal_verdicts_come_from_the_generator():
    world = World.of(Landmark("box", np.array([1.0, 0.0, 0.15])))
    loop = FakeLoop()
    device = ProgramInput(Program([parse_instruction("pick up the box", places=world.names()).steps[0]]), world,
                          start_delay_s=0.0)
    loop.connect(device)
    device.poll(0.0)
    (goal,) = device.runner.active_goals
    for k in range(1, 50):
        device.poll(k * 0.01)
    assert not device.done
    loop.feedback.goal_status[goal.goal_id] = "reached"
    device.poll(0.6)
    assert device.done and device.records[0].outcome.status == COMPLETED
    assert device.records[0].goal_id == goal.goal_id


def test_records_serialise():
    loop = FakeLoop()
    device = drive(ProgramInput(parse_instruction("turn left"), start_delay_s=0.0), loop)
    d = record_dict(device.records[0])
    assert d["kind"] == "turn" and d["verdict"]["ok"] is True and len(d["truth_end"]) == 4


def test_without_a_loop_the_estimator_pose_is_refused():
    device = ProgramInput(parse_instruction("turn left"), start_delay_s=0.0)
    with pytest.raises(RuntimeError, match="not attached"):
        device.poll(0.0)


def test_odometry_integrates_the_estimators_velocity_over_its_time_stamps():
    est = EstimatedState()
    odo = Odometry()
    odo.pose(est)
    for k in range(1, 101):  # 1 s at 0.5 m/s along +y, sampled every 10 ms
        est.t_s = k * 0.01
        est.base_linvel_w_mps = np.array([0.0, 0.5, 0.0])
        pose = odo.pose(est)
        odo.pose(est)  # polled twice between estimates: counted once
    assert pose.y_m == pytest.approx(0.5) and pose.x_m == 0.0


# --- the judge on hand-built cases with known answers ----------------------------------------------
def rec(step, start, end, turned=None, status=COMPLETED):
    return StepRecord(StepOutcome("1", step.kind, step.describe(), status, 0.0, 5.0), step, start, end, turned)


@pytest.mark.parametrize("end_x,ok", [(1.95, True), (2.19, True), (1.79, False), (2.25, False)])
def test_judge_walk_distance_within_ten_percent(end_x, ok):
    v = judge(rec(Walk(distance_m=2.0), PlanarPose(0, 0, 0), PlanarPose(end_x, 0.3, 0)), World(), None)
    assert v.ok is ok
    assert v.values["error_rel"] == pytest.approx(end_x / 2 - 1)
    assert v.values["lateral_m"] == pytest.approx(0.3)


def test_judge_walk_direction_is_relative_to_the_heading_at_its_start():
    # facing +y, walking backward 1 m ends 1 m toward -y
    v = judge(rec(Walk(distance_m=1.0, direction="backward"), PlanarPose(0, 0, math.pi / 2), PlanarPose(0, -1.02, 0.1)),
              World(), None)
    assert v.ok and v.values["distance_m"] == pytest.approx(1.02)


@pytest.mark.parametrize("turned_deg,ok", [(83.0, True), (97.0, True), (78.0, False), (-90.0, False)])
def test_judge_turn_within_ten_degrees(turned_deg, ok):
    v = judge(rec(Turn(angle_rad=math.pi / 2), PlanarPose(0, 0, 0), PlanarPose(0, 0, 1.0), math.radians(turned_deg)),
              World(), None)
    assert v.ok is ok


def test_judge_turn_to_face_a_place_and_to_a_heading():
    world = World.of(Landmark("door", np.array([0.0, 3.0, 0.0]), "point"))
    assert judge(rec(Turn(target="door"), PlanarPose(0, 0, 0), PlanarPose(0, 0, math.radians(95))), world, None).ok
    assert not judge(rec(Turn(target="door"), PlanarPose(0, 0, 0), PlanarPose(0, 0, math.radians(75))), world, None).ok
    assert judge(rec(Turn(heading_rad=math.pi), PlanarPose(0, 0, 0), PlanarPose(0, 0, -math.pi + 0.1)), world, None).ok


def test_judge_walk_to_a_place_stops_at_its_standoff():
    world = World.of(Landmark("box", np.array([3.0, 0.0, 0.15])))  # standoff 0.45 m: stop at x = 2.55
    assert judge(rec(Walk(target="box"), PlanarPose(0, 0, 0), PlanarPose(2.5, 0, 0)), world, None).ok
    assert not judge(rec(Walk(target="box"), PlanarPose(0, 0, 0), PlanarPose(2.1, 0, 0)), world, None).ok


def test_judge_height_and_stand():
    v = judge(rec(Height(pelvis_height_m=0.65), PlanarPose(0, 0, 0, 0.75), PlanarPose(0, 0, 0, 0.68)), World(), None)
    assert v.ok and v.values["error_m"] == pytest.approx(0.03)
    assert not judge(rec(Height(pelvis_height_m=0.65), PlanarPose(0, 0, 0), PlanarPose(0, 0, 0, 0.75)), World(), None).ok
    assert judge(rec(Stand(duration_s=2.0), PlanarPose(0, 0, 0), PlanarPose(0.05, 0, 0)), World(), None).ok
    assert not judge(rec(Stand(duration_s=2.0), PlanarPose(0, 0, 0), PlanarPose(0, 0, 0), status="timed_out"),
                     World(), None).ok


def test_judge_needs_ground_truth():
    assert judge(rec(Walk(distance_m=1.0), None, None), World(), None) is None


def test_a_walk_after_a_goal_starts_over_once_the_walking_policy_has_the_robot():
    """The execution layer holds the robot in a whole-body phase until the walk's motion makes it
    hand back; what the robot does meanwhile is not the walk's."""
    loop = FakeLoop()
    loop.feedback.phase = "whole_body"
    device = ProgramInput(parse_instruction("walk forward 1 meter"), start_delay_s=0.0)
    loop.connect(device)
    for _ in range(100):  # 1 s in the whole-body phase: the robot is moved 0.3 m by the hand-over
        cmd = device.poll(loop.t)
        assert cmd.vx_mps > 0, "the walk commands motion, which makes the layer hand back"
        loop.x += 0.003
        loop.step(Command(), 0.01)
    loop.feedback.phase = "locomotion"
    while not device.done and loop.t < 30:
        loop.step(device.poll(loop.t), 0.01)
    (walk,) = device.records
    assert walk.outcome.started_s >= 1.0 + 0.5 - 1e-6, "restarted HAND_BACK_SETTLE_S after the hand-back"
    assert walk.truth_start.x_m > 0.3, "measured from the restart, not from where the hand-over began"
    assert walk.verdict.ok and walk.truth_end.x_m - walk.truth_start.x_m == pytest.approx(1.0, abs=0.05)


def test_goal_verdicts_from_the_execution_layers_ground_truth():
    from g1_control.program.judge import goal_verdict

    assert goal_verdict({"kind": "reach", "status": "reached", "hand_error_mean_m": 0.004}).ok
    assert not goal_verdict({"kind": "reach", "status": "reached", "hand_error_mean_m": 0.05}).ok
    assert goal_verdict({"kind": "pick", "status": "reached", "box_rise_m": 0.1, "dropped": False}).ok
    assert not goal_verdict({"kind": "pick", "status": "reached", "box_rise_m": 0.1, "dropped": True}).ok
    place = {"kind": "place", "status": "reached", "place_error_xy_m": 0.006, "place_error_z_m": 0.0, "box_tilt_deg": 1.0}
    assert goal_verdict(place).ok
    assert not goal_verdict(dict(place, status="unfinished")).ok, "a box in place is no success the layer did not report"
    assert not goal_verdict(dict(place, place_error_xy_m=0.08)).ok
    assert goal_verdict({"kind": "step_up", "status": "reached", "both_feet_on_top_s": 2.0, "on_top_at_end": True}).ok
    assert not goal_verdict({"kind": "step_down", "status": "reached", "on_floor_at_end": False}).ok
    v = goal_verdict({"kind": "reach", "status": "failed", "message": "out of reach"})
    assert not v.ok and "out of reach" in v.text


class LocalisedLoop(FakeLoop):
    """As FakeLoop with a velocity odometry reading 80 %, plus the loop's localiser pose (ExecutionFeedback.pose)
    reading the true position, as a fused estimate would."""

    def _publish(self, v_w):
        super()._publish(v_w)
        from g1_control.types import WorldPose

        self.feedback.pose = WorldPose(self.t, self.x, self.y, 0.75, self.yaw)


def test_the_runner_steers_by_the_loops_localiser_pose_where_there_is_one():
    """The velocity odometry under-reads (it alone walks 2.5 m for 2 m: previous test); the localiser's
    pose reads true, and the runner steers by it: 2 m by ground truth."""
    loop = LocalisedLoop(odometry_scale=0.8)
    device = drive(ProgramInput(Program([Walk(distance_m=2.0)]), start_delay_s=0.0), loop)
    [walk] = device.records
    assert walk.truth_end.x_m == pytest.approx(2.0, abs=0.03)
