"""Goal execution in physics at small scale (the bench runs the full seeded suite): the tracking
layer with the goal generator in MuJoCo, judged from ground truth."""

import numpy as np
import pytest

from g1_control.scene import Box, SceneConfig, Table
from g1_control.teleop.scripted import GoalEntry, Segment
from g1_control.tools import execution_goals as G
from g1_control.tools.physics_trials import Trial, run_trial


def _trial(name, timeline, scene=None):
    return Trial(name, timeline, tracker="layer", tracker_hz=G.LAYER_HZ, scene=scene)


def test_a_reach_holds_the_hand_on_the_point_and_hands_back():
    point = G.reach_points("right", seed=3, n=1)[0]
    result = run_trial(_trial("reach", [
        Segment(1.5, label="stand"),
        Segment(4.5, label="reach", goals=[GoalEntry("reach", hand="right", pos_w_m=tuple(point))]),
        Segment(3.0, label="walk", vx_mps=0.3)]))
    assert not result.fell, result.fall
    (o,) = result.goals
    assert o["status"] == "reached" and o["within_tolerance"] >= 0.9 and o["hand_error_mean_m"] < 0.03
    # walking again: the policy has the robot (it moved forward)
    t, x = result.log["t_s"], result.log["base_pos_m"][:, 0]
    assert x[t > 8.5].mean() - x[(t > 5.0) & (t < 6.0)].mean() > 0.2


def test_a_standing_height_below_the_policys_range_under_the_wbc():
    result = run_trial(_trial("height", [Segment(1.5, label="stand", style="arms_out"),
                                         Segment(6.0, label="low", style="arms_out", pelvis_height_m=0.5)]))
    assert not result.fell, result.fall
    ((asked, measured),) = G.height_figures(result)
    assert abs(measured - asked) <= G.HEIGHT_TOLERANCE_M


def test_a_box_out_of_reach_is_refused_and_the_robot_stays_up():
    scene = SceneConfig(tables=[Table("table_a", (1.5, 0.0), (0.8, 0.8), 0.7)],
                        boxes=[Box("box", (1.5, 0.0), stands_on="table_a")])  # in the middle of a deep table
    scene.validate("scene")
    result = run_trial(_trial("refused", [Segment(1.0, label="stand"),
                                          Segment(3.0, label="pick", goals=[GoalEntry("pick", object="box")])], scene))
    assert not result.fell
    (o,) = result.goals
    # the stance search (generator/goals/stances.py) finds no stance: reaching the middle of a 0.8 m deep
    # table would put the pelvis inside the table's edge, and the refusal names that table
    assert o["status"] == "failed" and "no stance can pick it up" in o["message"] and "'table_a'" in o["message"]


@pytest.mark.slow
def test_box_picked_carried_and_placed_on_a_second_table():
    (trial,) = G.box_trials(n=1)(0)
    result = run_trial(trial)
    ok, err, note = G.box_outcome(result)
    assert ok, note
    assert err < G.PLACE_TOLERANCE_M


@pytest.mark.slow
def test_step_up_onto_a_platform_and_back_down():
    (trial,) = G.step_trials(n=1)(0)
    result = run_trial(trial)
    ok, note = G.step_outcome(result)
    assert ok, note


def test_seeded_layouts_are_valid_and_repeatable():
    a, _ = G.box_layout(0, 1)
    b, _ = G.box_layout(0, 1)
    assert a == b
    box = a.box("box")
    start = a.box_center(box)
    table_b = a.block("table_b")
    assert 2.0 == pytest.approx(float(np.hypot(*start[:2])), abs=1e-6)
    assert table_b.distance_xy(start[:2]) > 2.0
    points = G.reach_points("left", 0)
    assert len(points) == G.REACH_POINTS
    d = [np.linalg.norm(p - G.SHOULDER_W_M["left"]) for p in points]
    assert min(d) >= 0.2 - 1e-9 and max(d) <= 0.5 + 1e-9
