"""ProgramRunner against a kinematic stand-in (exact integration of the commands it emits)."""

import math

import numpy as np
import pytest

from g1_control.program import (
    COMPLETED,
    FAILED,
    TIMED_OUT,
    Landmark,
    Parallel,
    Pick,
    Place,
    Program,
    ProgramError,
    ProgramProgress,
    ProgramRunner,
    Reach,
    Repeat,
    RunnerConfig,
    Stand,
    StepUp,
    Style,
    Turn,
    Walk,
    World,
    parse_instruction,
)
from g1_control.program.kinematic import KinematicProgress, run_kinematic
from g1_control.program.runner import wrap_angle
from g1_control.robot import g1

WORLD = World.of(
    Landmark("table", np.array([3.0, 2.0, 0.4]), "surface"),
    Landmark("box", np.array([1.0, -1.0, 0.15])),
    Landmark("platform", np.array([-2.0, 0.0, 0.1]), "platform"),
)


def run(program, world=WORLD, **robot_kw):
    runner = ProgramRunner(program, world)
    robot = run_kinematic(runner, robot=KinematicProgress(**robot_kw))
    return runner, robot


def test_walk_two_meters_then_turn_ninety_degrees():
    runner, robot = run(parse_instruction("walk forward two meters, then turn left ninety degrees"))
    assert runner.done and not runner.stopped
    walk, turn = runner.outcomes
    assert (walk.status, turn.status) == (COMPLETED, COMPLETED)
    # measured by the runner from odometry at completion, and checked against the stand-in's own pose
    assert walk.measured["distance_m"] == pytest.approx(2.0, abs=0.03)
    assert abs(walk.measured["lateral_m"]) < 1e-9
    assert turn.measured["turned_rad"] == pytest.approx(math.pi / 2, abs=math.radians(2))
    assert robot.x_m == pytest.approx(2.0, abs=0.05) and abs(robot.y_m) < 0.01
    assert robot.yaw_rad == pytest.approx(math.pi / 2, abs=math.radians(3))
    assert 2.0 / 0.5 < walk.ended_s - walk.started_s < 2.0 / 0.5 + 3.0  # default speed 0.5 m/s, slowing at the end


def test_walk_distance_is_along_the_start_direction_from_any_pose():
    runner, robot = run(Program([Walk(distance_m=1.5, direction="left")]), x_m=1.0, y_m=1.0, yaw_rad=math.pi / 2)
    assert runner.outcomes[0].measured["distance_m"] == pytest.approx(1.5, abs=0.03)
    assert robot.x_m == pytest.approx(1.0 - 1.5, abs=0.05) and robot.y_m == pytest.approx(1.0, abs=0.01)


def test_turns_wrap_around_and_a_full_circle_is_a_full_circle():
    runner, robot = run(Program([Turn(angle_rad=2 * math.pi, direction="right")]), yaw_rad=3.0)
    out = runner.outcomes[0]
    assert out.status == COMPLETED
    assert out.measured["turned_rad"] == pytest.approx(-2 * math.pi, abs=math.radians(2))
    assert wrap_angle(robot.yaw_rad - 3.0) == pytest.approx(0.0, abs=math.radians(3))


def test_turn_to_a_heading_takes_the_shorter_way_across_pi():
    runner, _ = run(Program([Turn(heading_rad=-3.0)]), yaw_rad=3.0)
    out = runner.outcomes[0]
    assert out.status == COMPLETED
    assert out.measured["turned_rad"] == pytest.approx(2 * math.pi - 6.0, abs=math.radians(2))  # +0.28 rad, not -6


def test_walk_to_a_place_stops_at_its_standoff_facing_it():
    runner, robot = run(Program([Walk(target="table"), Turn(target="box")]))
    walk, turn = runner.outcomes
    assert walk.status == COMPLETED and turn.status == COMPLETED
    assert walk.measured["distance_to_place_m"] == pytest.approx(0.5, abs=0.1)  # surface standoff 0.5 m
    dist = math.hypot(3.0 - robot.x_m, 2.0 - robot.y_m)
    assert dist == pytest.approx(0.5, abs=0.12)
    bearing_to_box = math.atan2(-1.0 - robot.y_m, 1.0 - robot.x_m)
    assert wrap_angle(robot.yaw_rad - bearing_to_box) == pytest.approx(0.0, abs=math.radians(3))


def test_walk_back_to_the_start():
    runner, robot = run(parse_instruction("walk forward 2 m, turn left, walk forward 1 m, walk back to the start"))
    assert [o.status for o in runner.outcomes] == [COMPLETED] * 4
    assert math.hypot(robot.x_m, robot.y_m) < 0.1


def test_goal_steps_emit_goal_requests_and_complete_on_their_status():
    program = parse_instruction("pick up the box and put it on the table, then step onto the platform")
    runner = ProgramRunner(program, WORLD)
    cmd = runner.update(0.0, ProgramProgress())
    (goal,) = runner.active_goals
    assert (goal.kind, goal.object, goal.hand) == ("pick", "box", "both")
    np.testing.assert_allclose(goal.target_w_m, [1.0, -1.0, 0.15])
    assert [(g.frame, list(g.pos_w_m)) for g in cmd.goals] == [("box_pick", [1.0, -1.0, 0.15])]
    assert cmd.vx_mps == 0.0 and cmd.wz_radps == 0.0
    runner.update(5.0, ProgramProgress(goal_status={goal.goal_id: "reached"}))
    assert runner.outcomes[0].status == COMPLETED
    (place,) = runner.active_goals
    assert (place.kind, place.object, place.target) == ("place", "box", "table")
    np.testing.assert_allclose(place.target_w_m, [3.0, 2.0, 0.4])
    assert place.goal_id != goal.goal_id
    runner.update(9.0, ProgramProgress(goal_status={place.goal_id: "reached"}))
    cmd = runner.update(9.02, ProgramProgress())
    assert [g.frame for g in cmd.goals] == ["box_climb"]
    assert runner.current_label == "3"


def test_a_failed_goal_stops_the_program():
    runner, _ = run(Program([Pick("box"), Place("box", "table")]), goal_results={"pick": "failed"})
    assert runner.stopped and runner.done
    assert [(o.kind, o.status) for o in runner.outcomes] == [("pick", FAILED)]


def test_a_goal_that_never_comes_times_out_at_the_default():
    runner, _ = run(Program([StepUp("platform"), Stand(1.0)]), goal_results={"step_up": "never"})
    (out,) = runner.outcomes
    assert out.status == TIMED_OUT
    assert out.ended_s - out.started_s == pytest.approx(RunnerConfig().goal_timeout_s["step_up"], abs=0.05)


def test_a_walk_that_cannot_move_times_out_with_what_it_covered():
    program = Program([Walk(distance_m=2.0, timeout_s=3.0)])
    runner = ProgramRunner(program, WORLD)
    t = 0.0
    while not runner.done:
        runner.update(t, ProgramProgress())  # the robot is held in place
        t += 0.02
    (out,) = runner.outcomes
    assert out.status == TIMED_OUT and out.measured["distance_m"] == 0.0 and out.measured["error_m"] == -2.0


def test_reach_goals_map_to_hand_frames():
    runner = ProgramRunner(Program([Reach("left", "box"), Reach("both", None, (0.3, 0.0, 0.0))]), WORLD)
    cmd = runner.update(0.0, ProgramProgress())
    assert [g.frame for g in cmd.goals] == [g1.HAND_BODIES[0]]
    g = runner.active_goals[0]
    runner.update(0.1, ProgramProgress(goal_status={g.goal_id: "reached"}))
    (offset_goal,) = runner.active_goals
    np.testing.assert_allclose(offset_goal.offset_b_m, [0.3, 0.0, 0.0])
    assert offset_goal.target_w_m is None and offset_goal.to_effector_goals() == []


def test_parallel_style_rides_along_and_a_persistent_style_stays():
    program = Program([Style("guard"), Parallel(Walk(distance_m=0.5), [Style("wave")]), Style("dance", 1.0),
                       Stand(0.5)])
    runner = ProgramRunner(program, WORLD)
    robot = KinematicProgress()
    styles = []
    while not runner.done:
        cmd = runner.update(robot.t_s, robot.progress(runner.active_goals))
        styles.append((runner.current_label, cmd.style, cmd.vx_mps))
        robot.step(cmd, 0.02)
    assert {s for label, s, _ in styles if label == "2"} == {"wave"}
    # 0.5 m/s walking, slowing from the start of a walk this short (speed = gain x remaining)
    assert max(v for label, _, v in styles if label == "2") == pytest.approx(RunnerConfig().slowdown_gain_per_s * 0.5)
    assert {s for label, s, _ in styles if label == "3"} == {"dance"}
    assert {s for label, s, _ in styles if label == "4"} == {"guard"}  # back to the persistent style
    assert runner.update(robot.t_s, robot.progress()).style == "guard"


def test_repeats_are_expanded_and_labelled():
    runner, robot = run(Program([Repeat(4, [Walk(distance_m=1.0), Turn(angle_rad=math.pi / 2)])]))
    assert [o.label for o in runner.outcomes] == ["1.1#1", "1.2#1", "1.1#2", "1.2#2", "1.1#3", "1.2#3", "1.1#4",
                                                  "1.2#4"]
    assert all(o.status == COMPLETED for o in runner.outcomes)
    assert math.hypot(robot.x_m, robot.y_m) < 0.15  # a square brings it back


def test_height_steps_set_the_pelvis_height():
    runner = ProgramRunner(parse_instruction("crouch, then walk forward 1 m, then stand up"), WORLD)
    robot = KinematicProgress()
    heights = {}
    while not runner.done:
        cmd = runner.update(robot.t_s, robot.progress())
        heights.setdefault(runner.current_label, set()).add(cmd.pelvis_height_m)
        robot.step(cmd, 0.02)
    assert heights["1"] == {0.62} and heights["2"] == {0.62}
    assert runner.update(robot.t_s, robot.progress()).pelvis_height_m is None  # "stand up": the generator's own


def test_a_program_naming_a_place_the_world_lacks_is_refused():
    with pytest.raises(ProgramError, match=r"step 1 \(walk\).target: 'door' is not in the world"):
        ProgramRunner(Program([Walk(target="door")]), WORLD)


def test_every_command_is_valid():
    program = parse_instruction("wave while walking to the table; turn around twice and walk back to the start")
    runner = ProgramRunner(program, WORLD)
    robot = KinematicProgress()
    while not runner.done:
        cmd = runner.update(robot.t_s, robot.progress())
        assert abs(cmd.vx_mps) <= 0.5 + 1e-9 and abs(cmd.wz_radps) <= 0.6 + 1e-9
        robot.step(cmd, 0.02)
    assert [o.status for o in runner.outcomes] == [COMPLETED] * 4
