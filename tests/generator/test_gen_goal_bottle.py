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
