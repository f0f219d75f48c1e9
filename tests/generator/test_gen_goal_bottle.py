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
    scene = draw_scene(1, 1)
    scene["bottle"]["xy_m"] = (0.75, scene["bottle"]["xy_m"][1])
    loop = _run(scene, 3.5)
    msg = loop.generator.goal_messages.get("seg1.0", "")
    assert loop.generator.goal_status["seg1.0"] == "failed"
    assert "hand: the closest standing pose leaves the hand" in msg and "cm from the grasp" in msg
