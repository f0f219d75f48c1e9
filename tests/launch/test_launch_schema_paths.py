"""The launch schema's later branches, each error's exact words (mutation-run survivors, issue 16):
programs and instructions in the input, places, the generator model against the robot variant,
the tracking layer's rates and generator, goals' scene names, overrides, the bounds just past the limits."""

from __future__ import annotations

import json
import re

import pytest
import yaml

from g1_control.errors import LaunchFileError
from g1_control.launch.schema import InputConfig, load_launch, parse_launch
from tests.launch.launch_schema_data import DDS, launch_data
from tests.paths import LAUNCH_DIR


def _with(**sections) -> dict:
    return launch_data("paths", **sections)


def _program(input_section: dict, **extra) -> dict:
    data = yaml.safe_load((LAUNCH_DIR / "sim_program.yaml").read_text())
    data["input"] = {"type": "program", **input_section}
    data.update(extra)
    return data


def _refused(data: dict, message: str) -> None:
    with pytest.raises(LaunchFileError) as info:
        parse_launch(data)
    assert str(info.value) == message


# -- bounds just past the documented ones -------------------------------------------------------------
@pytest.mark.parametrize(("sections", "message"), [
    ({"backend": {**DDS, "domain": 233}},
     "<launch>: backend.domain: 233 is not a DDS domain id (0..232; the robot uses 0, simulation 1)"),
    ({"deploy": {"realtime_priority": 100}},
     "<launch>: deploy.realtime_priority: 100 is not a real-time priority (1..99, or 0 for normal scheduling)"),
    ({"input": {"type": "random", "start_delay_s": -0.5}}, "<launch>: input.start_delay_s: must be >= 0, got -0.5"),
])
def test_values_just_past_the_bounds_are_refused_in_words(sections, message):
    _refused(_with(**sections), message)


def test_a_zero_start_delay_is_accepted():
    assert parse_launch(_with(input={"type": "random", "start_delay_s": 0.0})).input.start_delay_s == 0.0
    assert parse_launch(_with(input={"type": "random", "start_delay_s": 0.5})).input.start_delay_s == 0.5


# -- programs, instructions, places --------------------------------------------------------------------
@pytest.mark.parametrize(("key", "value"), [("program", [{"kind": "stand", "duration_s": 1.0}]),
                                            ("instruction", "walk forward 1 m")])
def test_a_program_or_instruction_on_another_input_type_is_named(key, value):
    data = _with(input={"type": "scripted", "timeline": [{"duration_s": 1.0}], key: value})
    _refused(data, f"<launch>: input.{key}: only input.type program runs a program (got type scripted)")


def test_a_program_input_needs_exactly_one_of_program_and_instruction():
    words = "input.type program needs `program` (a list of steps) or `instruction` (English), one of them"
    _refused(_program({}), f"<launch>: input: {words}")
    _refused(_program({"program": [{"kind": "stand", "duration_s": 1.0}], "instruction": "wave"}),
             f"<launch>: input: {words}")
    with pytest.raises(LaunchFileError) as info:
        InputConfig(type="program").parsed_program()
    assert str(info.value) == f"input: {words}"


def test_program_step_errors_name_the_step_under_the_given_key():
    _refused(_program({"program": [{"kind": "stand", "duration_s": 1.0}, {"kind": "walk", "distance_m": -2.0}]}),
             "<launch>: input.program[1] (walk).distance_m: must be > 0; got -2")
    with pytest.raises(LaunchFileError, match=r"^mine\.program\[0\]\.kind: unknown step kind 'jump'"):
        InputConfig(type="program", program=[{"kind": "jump"}]).parsed_program("mine")
    with pytest.raises(LaunchFileError, match=r"^input\.program\[0\]\.kind: unknown step kind 'jump'"):
        InputConfig(type="program", program=[{"kind": "jump"}]).parsed_program()


def test_an_instruction_error_names_the_key():
    with pytest.raises(LaunchFileError, match=r"^<launch>: input\.instruction: unknown word 'wlak'"):
        parse_launch(_program({"instruction": "wlak forward 2 meters"}))
    with pytest.raises(LaunchFileError, match=r"^input\.instruction: unknown word 'wlak'"):
        InputConfig(type="program", instruction="wlak forward 2 meters").parsed_program()


def test_places_errors_name_the_key():
    bad = {"door": {"pos_w_m": [3, 0, 0], "kind": "portal"}}
    with pytest.raises(LaunchFileError, match=r"^<launch>: input\.places\.door\.kind: 'portal' is not one of"):
        parse_launch(_program({"instruction": "walk to the door", "places": bad}))
    with pytest.raises(LaunchFileError, match=r"^input\.places\.door\.kind: 'portal' is not one of"):
        InputConfig(type="program", places=bad).world()
    with pytest.raises(LaunchFileError, match=r"^here\.places\.door\.kind: 'portal' is not one of"):
        InputConfig(type="program", places=bad).world("here")


def test_a_program_walks_to_places_of_the_input_and_of_the_scene():
    door = {"door": {"pos_w_m": [3, 0, 0], "kind": "point"}}
    launch = parse_launch(_program({"instruction": "walk to the door", "places": door}))
    assert launch.program_world().places["door"].kind == "point"
    _refused(_program({"instruction": "walk to the door"}),
             "<launch>: input.program: step 1 (walk).target: 'door' is not in the world; known: start")
    table = {"tables": [{"name": "door", "center_xy_m": [2.0, 0.0], "size_xy_m": [0.5, 0.8], "height_m": 0.7}]}
    _refused(_program({"instruction": "walk to the door", "places": door}, scene=table),
             "<launch>: input.places.door: the scene already has a 'door'; name it otherwise")


# -- the generator model serves the robot --------------------------------------------------------------
def _model(tmp_path, skeletons=None):
    folder = tmp_path / "model"
    folder.mkdir()
    (folder / "backbone.onnx").write_bytes(b"")
    (folder / "model.json").write_text(json.dumps({} if skeletons is None else {"skeletons": skeletons}))
    return folder


@pytest.mark.parametrize("gtype", ["backbone", "learned_motion_matching", "motion_matching"])
def test_a_variant_without_a_generator_skeleton_is_refused_by_every_learned_generator(gtype):
    data = _with(generator={"type": gtype}, backend={"expected_variant": "g1_29dof_locked_waist"})
    with pytest.raises(LaunchFileError, match=r"^<launch>: generator\.model: the generator has no model for robot "
                                              r"variant 'g1_29dof_locked_waist'.*\(backend\.expected_variant "
                                              r"g1_29dof_locked_waist, backend\.hands none\)$"):
        parse_launch(data)
    parse_launch(_with(generator={"type": "velocity"}, backend={"expected_variant": "g1_29dof_locked_waist"}))


@pytest.mark.parametrize("as_folder", [True, False])
def test_a_model_trained_for_other_skeletons_is_refused(tmp_path, as_folder):
    folder = _model(tmp_path, ["g1_23dof", "g1_29dof"])
    model = folder if as_folder else folder / "backbone.onnx"
    parse_launch(_with(generator={"type": "backbone", "model": str(model)}))
    parse_launch(_with(generator={"type": "backbone", "model": str(model)}, backend={"expected_variant": "g1_23dof"}))
    _refused(_with(generator={"type": "backbone", "model": str(model)}, backend={"hands": "dex3"}),
             f"<launch>: generator.model: {model} was trained for g1_23dof, g1_29dof; the robot is g1_29dof_with_hand "
             "(backend.expected_variant g1_29dof, backend.hands dex3)")


def test_a_model_without_a_skeleton_list_serves_the_29dof_robot(tmp_path):
    model = _model(tmp_path)
    parse_launch(_with(generator={"type": "learned_motion_matching", "model": str(model)}))
    with pytest.raises(LaunchFileError, match=r"was trained for g1_29dof; the robot is g1_23dof"):
        parse_launch(_with(generator={"type": "learned_motion_matching", "model": str(model)},
                           backend={"expected_variant": "g1_23dof"}))


def test_motion_matching_models_and_the_shipped_model_are_not_read(tmp_path, monkeypatch):
    from pathlib import Path

    model = _model(tmp_path, ["g1_23dof"])
    read: list[Path] = []
    real_read_text = Path.read_text

    def spy(self, *args, **kwargs):
        read.append(Path(self).resolve())
        return real_read_text(self, *args, **kwargs)

    monkeypatch.setattr(Path, "read_text", spy)
    launch = parse_launch(_with(generator={"type": "motion_matching", "model": str(model)}))
    assert (launch.generator.type, launch.generator.model) == ("motion_matching", str(model))
    monkeypatch.chdir(model)  # a model.json in the working directory is no model of the launch file
    launch = parse_launch(_with(generator={"type": "backbone"}))
    assert launch.generator.model in ("", None)
    assert not [p for p in read if p.is_relative_to(model.resolve())], f"model files were read: {read}"
    # The spy sees the reads it is meant to catch: a backbone model's model.json is read.
    parse_launch(_with(generator={"type": "backbone", "model": str(model)}, backend={"expected_variant": "g1_23dof"}))
    assert model.resolve() / "model.json" in read


# -- the tracking layer --------------------------------------------------------------------------------
def test_the_layer_needs_the_wbc_rate_and_a_walking_generator():
    _refused(_with(tracker={"type": "layer"}, rates={"tracker_hz": 50}),
             "<launch>: rates.tracker_hz: 50 Hz is too slow for tracker.type layer (the whole-body controller needs "
             ">= 100 Hz, e.g. 100)")
    _refused(_with(tracker={"type": "layer"}, rates={"tracker_hz": 100}, generator={"type": "scripted"}),
             "<launch>: generator.type: tracker.type layer plans its own whole-body phases; use velocity (or backbone) "
             "for the walking in between, not scripted")
    _refused(_with(tracker={"type": "layer"}, rates={"tracker_hz": 125}),
             "<launch>: rates.tracker_hz: 125 Hz; tracker.type layer runs the 50 Hz walking policy every n-th tick, "
             "so use a multiple of 50 (e.g. 100)")
    assert parse_launch(_with(tracker={"type": "layer"}, rates={"tracker_hz": 100})).tracker.type == "layer"


# -- goals name what the scene has ---------------------------------------------------------------------
SCENE = {"tables": [{"name": "table_a", "center_xy_m": [2.0, 0.0], "size_xy_m": [0.5, 0.8], "height_m": 0.7}],
         "platforms": [{"name": "step", "center_xy_m": [0.0, 2.0], "size_xy_m": [0.6, 1.0], "height_m": 0.15}],
         "boxes": [{"name": "box", "stands_on": "table_a", "xy_m": [1.9, 0.0]}]}


def _goals(goals, scene=SCENE, tracker="layer"):
    return _with(rates={"tracker_hz": 100}, tracker={"type": tracker}, scene=scene,
                 input={"type": "scripted", "timeline": [{"duration_s": 2}, {"duration_s": 10, "goals": goals}]})


G = "<launch>: input.timeline[1].goals[0]"


@pytest.mark.parametrize(("goal", "scene", "message"), [
    ({"kind": "pick", "object": "crate"}, SCENE, f"{G}.object: 'crate' is not a box or bottle of the scene; known: box"),
    ({"kind": "pick", "object": "crate"}, {**SCENE, "boxes": [*SCENE["boxes"], {"name": "box2", "xy_m": [1.0, 1.0]}]},
     f"{G}.object: 'crate' is not a box or bottle of the scene; known: box, box2"),
    ({"kind": "pick", "object": "crate"}, {}, f"{G}.object: 'crate' is not a box or bottle of the scene; known: none "
                                              "(scene.boxes and scene.bottles are empty)"),
    ({"kind": "place", "target": "shelf"}, SCENE, f"{G}.target: 'shelf' is not a place of the scene; known: table_a, "
                                                  "step, floor"),
    ({"kind": "place", "target": "step"}, {"platforms": SCENE["platforms"]}, f"{G}: a place goal needs a box in "
                                                                              "scene.boxes (or a bottle in scene.bottles)"),
    ({"kind": "pick"}, {}, f"{G}: a pick goal needs a box in scene.boxes (or a bottle in scene.bottles)"),
    ({"kind": "step_up", "target": "table_a"}, SCENE, f"{G}.target: 'table_a' is not a platform of the scene; "
                                                      "known: step"),
    ({"kind": "step_down", "target": "box"}, SCENE, f"{G}.target: 'box' is not a platform of the scene; known: step"),
    ({"kind": "step_down", "target": "box"}, {}, f"{G}.target: 'box' is not a platform of the scene; known: none"),
    ({"kind": "step_up"}, {}, f"{G}: a step_up goal needs a platform in scene.platforms"),
    ({"kind": "reach", "hand": "left", "target": "shelf", "offset_h_m": [0.2, 0, 0]}, SCENE,
     f"{G}.target: 'shelf' is not a place of the scene; known: table_a, step, box"),
])
def test_goal_errors_name_the_key_and_what_the_scene_has(goal, scene, message):
    _refused(_goals([goal], scene), message)


BOTTLE_SCENE = {"tables": SCENE["tables"], "bottles": [{"name": "bottle", "stands_on": "table_a", "xy_m": [1.9, 0.2]}]}


def test_a_bottle_goal_takes_one_dex3_hand_and_names_its_bottle():
    wbc = {"rates": {"tracker_hz": 250}, "tracker": {"type": "wbc"}, "generator": {"type": "velocity"}}
    pick = {"kind": "pick", "object": "bottle", "hand": "right"}
    _refused({**_goals([pick], BOTTLE_SCENE), **wbc},
             f"{G}: picking bottle 'bottle' takes a Dex3 hand (backend.hands: dex3; got none)")
    dex3 = {**wbc, "backend": {"type": "mujoco", "hands": "dex3"}}
    _refused({**_goals([{**pick, "hand": "both"}], BOTTLE_SCENE), **dex3},
             f"{G}.hand: a bottle is picked with one hand (left or right)")
    _refused({**_goals([{**pick, "object": "cup"}], BOTTLE_SCENE), **dex3},
             f"{G}.object: 'cup' is not a box or bottle of the scene; known: bottle")
    _refused({**_goals([pick], BOTTLE_SCENE), **wbc, "backend": {**DDS, "hands": "dex3"}},
             f"{G}: picking bottle 'bottle' needs the simulator for now (backend.type mujoco; got unitree_dds): on the "
             "robot the loop does not drive the Dex3 fingers yet (`g1 hands grasp` does, alone)")
    launch = parse_launch({**_goals([pick], BOTTLE_SCENE), **dex3})
    assert launch.executes_goals and launch.scene.bottle("bottle") is not None


@pytest.mark.parametrize(("bottle", "message"), [
    ({"radius_m": 0.06}, "scene.bottles[0].radius_m: 0.06 m is outside [0.02, 0.05] m (what one Dex3 hand closes around)"),
    ({"height_m": 0.5}, "scene.bottles[0].height_m: 0.5 m is outside [0.08, 0.35] m"),
    ({"mass_kg": 2.0}, "scene.bottles[0].mass_kg: 2.0 kg is outside (0, 1.5] kg (one hand)"),
    ({"stands_on": "shelf"}, "scene.bottles[0].stands_on: 'shelf' is not a table or platform of the scene"),
    ({"xy_m": [2.6, 0.2]}, "scene.bottles[0].xy_m: [2.6, 0.2] is not over the top of 'table_a'"),
    ({"name": "table_a"}, "scene.bottles[0].name: 'table_a' is already used by scene.tables[0]"),
])
def test_a_bad_bottle_is_refused_naming_its_key(bottle, message):
    scene = {**BOTTLE_SCENE, "bottles": [{**BOTTLE_SCENE["bottles"][0], **bottle}]}
    with pytest.raises(LaunchFileError, match="^<launch>: " + re.escape(message)):
        parse_launch(_with(scene=scene))


def test_goals_name_their_tracker_and_reach_any_scene_name():
    _refused(_goals([{"kind": "pick", "object": "box"}], tracker="policy"),
             f"{G}: goals are executed by tracker.type layer (got policy; or wbc with a scene and a generator other than scripted)")
    reach = {"kind": "reach", "hand": "left", "target": "box", "offset_h_m": [0.2, 0, 0]}
    assert parse_launch(_goals([reach])).input.timeline[1].goals[0].target == "box"
    assert parse_launch(_goals([{"kind": "step_down", "target": "step"}])).input.timeline[1].goals[0].kind == "step_down"


def test_with_perception_a_step_goal_may_name_a_platform_the_scene_does_not_list_but_not_a_table():
    seen = {"steer_by": "estimate", "perception": {"interface": "lo", "domain": 1}}
    unseen = _goals([{"kind": "step_up", "target": "stage"}], scene={})
    _refused(unseen, f"{G}.target: 'stage' is not a platform of the scene; known: none")
    launch = parse_launch({**unseen, "estimation": seen})
    assert launch.input.timeline[1].goals[0].target == "stage" and not launch.scene.platforms
    assert parse_launch({**_goals([{"kind": "step_up"}], scene={}), "estimation": seen}).scene.empty
    _refused({**_goals([{"kind": "step_up", "target": "table_a"}]), "estimation": seen},
             f"{G}.target: 'table_a' is not a platform of the scene; known: step")


# -- load_launch: overrides ----------------------------------------------------------------------------
def test_overrides_are_applied_before_validation_and_their_errors_name_the_file():
    path = LAUNCH_DIR / "sim_walk.yaml"
    assert load_launch(path, ["duration_s=3.5"]).duration_s == 3.5
    with pytest.raises(LaunchFileError) as info:
        load_launch(path, ["duration_s"])
    assert str(info.value) == (f"{path}: --set 'duration_s': expected KEY=VALUE, e.g. "
                               "tracker.policy=holosoma_loco_fastsac")
    with pytest.raises(LaunchFileError, match=re.escape(f"{path}: duration_s: must be > 0, got -1")):
        load_launch(path, ["duration_s=-1"])
