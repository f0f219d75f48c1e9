"""Scenes and goals in launch files: validated with the rest of the schema, errors name the key."""

import pytest
import yaml

from g1_control.errors import LaunchFileError
from g1_control.launch.schema import load_launch, parse_launch
from tests.paths import LAUNCH_DIR

SCENE = {"tables": [{"name": "table_a", "center_xy_m": [2.0, 0.0], "size_xy_m": [0.5, 0.8], "height_m": 0.7}],
         "platforms": [{"name": "step", "center_xy_m": [0.0, 2.0], "size_xy_m": [0.6, 1.0], "height_m": 0.15}],
         "boxes": [{"name": "box", "stands_on": "table_a", "xy_m": [1.9, 0.0]}]}


def _launch(goals, tracker="layer", scene=SCENE, hz=100):
    return {"name": "goals", "rates": {"tracker_hz": hz}, "tracker": {"type": tracker}, "scene": scene,
            "input": {"type": "scripted", "timeline": [{"duration_s": 2}, {"duration_s": 10, "goals": goals}]}}


@pytest.mark.parametrize("name", ["sim_reach", "sim_box", "sim_step"])
def test_the_goal_launch_files_validate(name):
    launch = load_launch(LAUNCH_DIR / f"{name}.yaml")
    assert launch.tracker.type == "layer" and launch.rates.tracker_hz == 100.0
    assert any(seg.goals for seg in launch.input.timeline)


def test_goals_and_scene_parse():
    launch = parse_launch(_launch([{"kind": "pick", "object": "box"},
                                   {"kind": "place", "object": "box", "target": "table_a", "pos_w_m": [1.9, 0.2, 0.85]},
                                   {"kind": "step_up", "target": "step"},
                                   {"kind": "reach", "hand": "left", "offset_h_m": [0.2, 0.0, 0.1]}]))
    goals = launch.input.timeline[1].goals
    assert [g.kind for g in goals] == ["pick", "place", "step_up", "reach"]
    assert launch.scene.box("box").stands_on == "table_a"


@pytest.mark.parametrize("goals, tracker, hz, message", [
    ([{"kind": "pick", "object": "crate"}], "layer", 100, "input.timeline[1].goals[0].object: 'crate' is not a box"),
    ([{"kind": "place", "target": "shelf"}], "layer", 100, "input.timeline[1].goals[0].target: 'shelf' is not a place"),
    ([{"kind": "step_up", "target": "table_a"}], "layer", 100, "'table_a' is not a platform"),
    ([{"kind": "reach", "hand": "right"}], "layer", 100, "a reach goal needs pos_w_m or offset_h_m"),
    ([{"kind": "reach", "hand": "middle", "pos_w_m": [0.3, 0, 1]}], "layer", 100, "input.timeline[1].goals[0].hand"),
    ([{"kind": "jump"}], "layer", 100, "input.timeline[1].goals[0].kind"),
    ([{"kind": "pick", "object": "box"}], "policy", 50, "goals are executed by tracker.type layer"),
    ([], "layer", 125, "use a multiple of 50"),
])
def test_bad_goals_are_refused_naming_the_key(goals, tracker, hz, message):
    with pytest.raises(LaunchFileError, match=message.replace("[", r"\[").replace("]", r"\]").replace(".", r"\.")):
        parse_launch(_launch(goals, tracker, hz=hz))


def test_a_scene_error_names_the_key():
    scene = yaml.safe_load("boxes: [{name: box, stands_on: table_a, xy_m: [1.9, 0.0]}]")
    with pytest.raises(LaunchFileError, match=r"scene\.boxes\[0\]\.stands_on: 'table_a' is not a table"):
        parse_launch(_launch([], scene=scene))
    # YAML reads a key `on` as true: the field is called stands_on, and the error says what is allowed
    with pytest.raises(LaunchFileError, match="allowed: name, xy_m, stands_on"):
        parse_launch(_launch([], scene=yaml.safe_load("boxes: [{name: box, on: floor, xy_m: [1.9, 0.0]}]")))


@pytest.mark.parametrize("overrides, after_s", [([], 0.03), (["rates.tracker_hz=200", "rates.lowlevel_hz=200"], 0.015),
                                                (["safety.command_hold_ticks=5"], 0.05),
                                                (["safety.command_hold_ticks=0"], 0.03)])
def test_a_plan_pauses_after_the_robot_links_command_life(overrides, after_s):
    """GoalConfig.plan_pause_after_s from the launch file: max(command_hold_ticks, 3) tracker ticks."""
    from g1_control.launch.builder import make_generator

    launch = load_launch(LAUNCH_DIR / "sim2sim_step.yaml", overrides=overrides)
    assert make_generator(launch).config.plan_pause_after_s == pytest.approx(after_s)
