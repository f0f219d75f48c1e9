"""generator/goals/bottle.py: a bottle pick refuses, before anything moves and saying why, where nothing
drives the fingers, or where the bottle is too short to grasp above its support or out of reach."""

from __future__ import annotations

import pytest

from g1_control.generator.goals.bottle import grasp_height
from g1_control.generator.goals.poses import ReachRefused
from g1_control.launch.builder import build_loop
from g1_control.scene import Bottle
from g1_control.tools.bench_bottle import draw_scene, scene_launch


def _run(scene: dict, seconds: float, fingers: bool | None = None):
    loop = build_loop(scene_launch(scene))
    if fingers is not None:
        loop.generator.ctx.fingers_driven = fingers
    loop.reset()
    loop.run(seconds)
    return loop


def test_a_bottle_pick_with_no_fingers_driven_refuses_before_the_arm_moves():
    scene = draw_scene(1, 1)
    loop = _run(scene, 3.0, fingers=False)
    gen = loop.generator
    assert gen.goal_status == {"seg1.0": "failed"}
    assert "nothing drives the fingers here" in gen.goal_messages["seg1.0"]
    assert not loop.fell


def test_the_builder_tells_the_goals_the_simulated_fingers_are_driven():
    loop = build_loop(scene_launch(draw_scene(1, 1)))
    assert loop.hands is not None and loop.generator.ctx.fingers_driven


def test_a_bottle_too_short_to_grasp_is_refused_naming_its_height():
    with pytest.raises(ReachRefused, match=r"bottle 'b' is 0.09 m tall: a Dex3 hand grasps it 0.07 m or more above"):
        grasp_height(Bottle("b", (0.4, 0.0), height_m=0.09))
    assert grasp_height(Bottle("b", (0.4, 0.0), height_m=0.22)) == pytest.approx(0.11)
    assert grasp_height(Bottle("b", (0.4, 0.0), height_m=0.11)) == pytest.approx(0.07)  # the lowest it grasps


def test_a_bottle_out_of_reach_is_refused_with_the_closest_pose():
    """Within reach from where the robot stands (no walk), but on a 1.45 m shelf: no upright hand gets there."""
    scene = draw_scene(1, 1)
    scene.update(table={"center_xy_m": [0.61, 0.0], "yaw_rad": 0.0}, table_height_m=1.45, hand="right")
    scene["bottle"]["xy_m"] = (0.43, -0.16)
    loop = _run(scene, 3.5)
    msg = loop.generator.goal_messages.get("seg1.0", "")
    assert loop.generator.goal_status["seg1.0"] == "failed"
    assert "hand: the closest standing pose leaves the hand" in msg and "cm from the grasp" in msg


def test_the_stance_for_a_bottle_faces_its_tables_near_side_with_the_bottle_by_the_picking_hand():
    import math

    import numpy as np

    from g1_control.generator.goals.bottle import PELVIS_TO_STANCE_MID_M, STANCE_AHEAD_M, STANCE_SIDE_M, bottle_stance
    from g1_control.generator.goals.context import GoalConfig, GoalContext
    from g1_control.scene import SceneConfig, Table

    yaw = math.radians(30.0)
    table = Table("t", (1.5, 0.5), (0.5, 0.9), 0.75, yaw_rad=yaw)
    xy = np.array(table.center) + np.array([[math.cos(yaw), -math.sin(yaw)], [math.sin(yaw), math.cos(yaw)]]) @ (-0.15, 0.1)
    bottle = Bottle("b", (float(xy[0]), float(xy[1])), stands_on="t")
    ctx = GoalContext(SceneConfig(tables=[table], bottles=[bottle]), GoalConfig())
    for hand, side in ((1, -1.0), (0, 1.0)):
        a = bottle_stance(ctx, bottle, hand)
        assert a is not None and abs(a.heading - yaw) < 1e-9, "facing the table's -x side, square on"
        pelvis = a.pelvis_xy()
        c, s = math.cos(a.heading), math.sin(a.heading)
        d = np.array([[c, s], [-s, c]]) @ (xy - pelvis)
        assert np.allclose(d, (STANCE_AHEAD_M, side * STANCE_SIDE_M)), d
        assert np.allclose(a.mid_xy - pelvis, PELVIS_TO_STANCE_MID_M * np.array([c, s]))
    assert bottle_stance(ctx, Bottle("f", (2.0, 2.0)), 1) is None, "on the floor: no table side to face"


def test_a_held_bottles_moment_turns_with_the_robot_as_computed_afresh_at_the_new_heading():
    """The executor turns the held bottle's moment with the plan's yaw (a carry turns the robot): at each
    heading it must be what held_wrench computes for a pick made facing that way; its weight stays."""
    import numpy as np

    from g1_control.generator.goals.bottle import held_wrench, turned_moments
    from g1_control.generator.goals.context import HeldBottle

    bottle = Bottle("b", (1.0, 0.0), mass_kg=0.6)
    for hand in (0, 1):
        h0 = 0.4
        held = HeldBottle(bottle, hand, 0.1, h0, *held_wrench(bottle, hand, h0))
        assert np.abs(held.moments_w_nm[hand]).max() > 0.01  # the weight hangs inside the palm: a real moment
        out = np.full((2, 3), np.nan)
        for yaw in (h0, h0 + 0.5, h0 - 2.0, h0 + np.pi):
            turned_moments(held, yaw, out)
            _, fresh = held_wrench(bottle, hand, yaw)
            assert np.allclose(out, fresh, atol=1e-12), (hand, yaw)
        turned_moments(held, h0 + np.pi / 2, out)
        assert not np.allclose(out, held.moments_w_nm)


def test_a_place_on_another_table_stands_facing_its_near_side_with_the_point_by_the_holding_hand():
    import math

    import numpy as np

    from g1_control.generator.goals.bottle import STANCE_AHEAD_M, STANCE_SIDE_M, place_stance
    from g1_control.generator.goals.context import GoalConfig, GoalContext
    from g1_control.scene import SceneConfig, Table

    yaw = math.radians(-70.0)
    table = Table("t2", (0.6, -1.2), (0.5, 0.9), 0.8, yaw_rad=yaw)
    rot = np.array([[math.cos(yaw), -math.sin(yaw)], [math.sin(yaw), math.cos(yaw)]])
    point = np.array(table.center) + rot @ (-0.17, -0.1)  # near its -x side
    ctx = GoalContext(SceneConfig(tables=[table]), GoalConfig())
    for hand, side in ((0, 1.0), (1, -1.0)):
        a = place_stance(ctx, point, "t2", hand)
        assert abs(a.heading - yaw) < 1e-9, "square on to the table's side nearest the point"
        c, s = math.cos(a.heading), math.sin(a.heading)
        d = np.array([[c, s], [-s, c]]) @ (point - a.pelvis_xy())
        assert np.allclose(d, (STANCE_AHEAD_M, side * STANCE_SIDE_M)), d
