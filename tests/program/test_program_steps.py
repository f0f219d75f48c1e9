"""Program steps: validation names the step and field, dict/JSON/YAML round trips, describe()."""

import math

import pytest

from g1_control.program import (
    Height,
    Landmark,
    Parallel,
    Pick,
    Place,
    Program,
    ProgramError,
    Reach,
    Repeat,
    Stand,
    StepDown,
    StepUp,
    Style,
    Turn,
    Walk,
    World,
    load_program,
    save_program,
)

EVERY_KIND = Program([
    Walk(distance_m=2.0, speed_mps=0.4),
    Walk(duration_s=3.0, direction="left"),
    Walk(target="table", timeout_s=20.0),
    Walk(distance_m=1.0, heading_rad=0.5),
    Turn(angle_rad=math.pi / 2, direction="right", yaw_rate_radps=0.3),
    Turn(heading_rad=-1.0),
    Turn(target="box"),
    Stand(2.0),
    Style("wave", 3.0),
    Style("guard"),
    Height(posture="crouch"),
    Height(pelvis_height_m=0.7, duration_s=2.0),
    Reach("left", "cup"),
    Reach("right", None, (0.3, 0.0, 0.1)),
    Pick("box", "both"),
    Place("box", "table"),
    Place("box"),
    StepUp("platform"),
    StepDown(),
    Parallel(Walk(target="table"), [Style("wave"), Height(posture="crouch")]),
    Repeat(3, [Walk(distance_m=1.0), Turn(angle_rad=math.pi / 2)]),
], source="hand written")


def test_every_kind_round_trips_through_dicts():
    data = EVERY_KIND.validate().to_dict()
    again = Program.from_dict(data)
    assert again.to_dict() == data
    assert again == EVERY_KIND


@pytest.mark.parametrize("suffix", [".json", ".yaml"])
def test_programs_round_trip_through_files(tmp_path, suffix):
    path = tmp_path / f"program{suffix}"
    save_program(EVERY_KIND, path)
    assert load_program(path) == EVERY_KIND


def test_to_dict_leaves_defaults_out():
    assert Walk(distance_m=2.0).to_dict() == {"kind": "walk", "distance_m": 2.0}
    assert Pick("box").to_dict() == {"kind": "pick", "object": "box"}
    assert Repeat(2, [Stand(1.0)]).to_dict() == {"kind": "repeat", "count": 2,
                                                 "steps": [{"kind": "stand", "duration_s": 1.0}]}


def test_a_bare_list_of_steps_is_a_program():
    assert Program.from_dict([{"kind": "stand", "duration_s": 1}]).steps == [Stand(1.0)]


@pytest.mark.parametrize("steps,message", [
    ([Walk(distance_m=-2.0)], "step 1 (walk).distance_m: must be > 0; got -2"),
    ([Stand(1.0), Walk(distance_m=float("nan"))], "step 2 (walk).distance_m: must be a finite number; got nan"),
    ([Walk()], "step 1 (walk): needs exactly one of distance_m, duration_s, target; got none"),
    ([Walk(distance_m=1.0, target="table")],
     "step 1 (walk): needs exactly one of distance_m, duration_s, target; got distance_m and target"),
    ([Walk(distance_m=1.0, direction="up")], "step 1 (walk).direction: 'up' is not one of forward, backward, left, right"),
    ([Walk(distance_m=1.0, speed_mps=3.0)], "step 1 (walk).speed_mps: must be <= 1.5; got 3"),
    ([Walk(target="other table")],
     "step 1 (walk).target: must be an object name without spaces (e.g. 'other_table'); got 'other table'"),
    ([Turn(angle_rad=1.0, heading_rad=0.0)],
     "step 1 (turn): needs exactly one of angle_rad, heading_rad, target; got angle_rad and heading_rad"),
    ([Turn(target="box", direction="right")], "step 1 (turn).direction: only a turn by an angle has a direction; "
                                              "a turn to a heading or a place takes the shorter way"),
    ([Stand(0.0)], "step 1 (stand).duration_s: must be > 0; got 0"),
    ([Style("moonwalk")], "step 1 (style).name: unknown style 'moonwalk'; known styles: default, carry, arms_out, "
                          "wave, guard, arm_swing, reach_up, look_around, dance, climb, lift"),
    ([Height(pelvis_height_m=1.5)], "step 1 (height).pelvis_height_m: must be within [0.3, 0.9] m; got 1.5"),
    ([Height(posture="kneel")], "step 1 (height).posture: 'kneel' is not one of crouch, normal, tall"),
    ([Reach("left")], "step 1 (reach): needs a target, an offset_m, or both"),
    ([Reach("left", None, (2.0, 0.0, 0.0))], "step 1 (reach).offset_m: longer than 1.0 m; got (2.0, 0.0, 0.0)"),
    ([Pick("")], "step 1 (pick).object: an object name is required"),
    ([Place("box", timeout_s=-1.0)], "step 1 (place).timeout_s: must be > 0; got -1"),
    ([StepUp("")], "step 1 (step_up).platform: an object name is required"),
    ([Parallel(Pick("box"), [Style("wave")])], "step 1 (parallel).main: must be a walk, turn or stand step; got 'pick'"),
    ([Parallel(Walk(distance_m=1.0), [Style("wave", 2.0)])],
     "step 1 (parallel).alongside[0] (style).duration_s: a step alongside lasts as long as the main step; "
     "leave it out"),
    ([Parallel(Walk(distance_m=1.0), [Pick("box")])],
     "step 1 (parallel).alongside[0] (pick): only style, height and reach steps run alongside; got 'pick'"),
    ([Repeat(0, [Stand(1.0)])], "step 1 (repeat).count: must be a whole number in [1, 100]; got 0"),
    ([Repeat(2, [Walk(distance_m=-1.0)])], "step 1 (repeat).steps[0] (walk).distance_m: must be > 0; got -1"),
    ([], "program: has no steps"),
])
def test_validation_names_the_step_and_field(steps, message):
    with pytest.raises(ProgramError) as info:
        Program(steps).validate()
    assert str(info.value) == message


@pytest.mark.parametrize("data,message", [
    ([{"kind": "fly"}], "step 1.kind: unknown step kind 'fly'; known: walk, turn, stand, style, height, reach, "
                        "pick, place, step_up, step_down, parallel, repeat"),
    ([{"kind": "walk", "distanse_m": 2}], "step 1 (walk): unknown field 'distanse_m'; known: distance_m, duration_s, "
                                          "target, direction, heading_rad, speed_mps, timeout_s"),
    ([{"kind": "walk", "distance_m": "far"}], "step 1 (walk).distance_m: must be a number; got 'far'"),
    ([{"kind": "pick"}], "step 1 (pick): missing field(s) object"),
    ([{"kind": "repeat", "count": 2.5, "steps": []}], "step 1 (repeat).count: must be a whole number; got 2.5"),
    ([{"kind": "parallel", "main": {"kind": "walk", "distance_m": 1}, "alongside": [{"kind": "style"}]}],
     "step 1 (parallel).alongside[0] (style): missing field(s) name"),
    ({"steps": [], "author": "x"}, "program: unknown field(s) ['author']; known: steps, source"),
])
def test_from_dict_refuses_bad_data(data, message):
    with pytest.raises(ProgramError) as info:
        Program.from_dict(data)
    assert str(info.value) == message


def test_place_names_are_checked_against_a_world():
    world = World.of(Landmark("table", [1.0, 0.0, 0.4], "surface"))
    Program([Walk(target="table"), Walk(target="start")]).validate(world)
    with pytest.raises(ProgramError, match=r"^step 2 \(place\).target: 'shelf' is not in the world; known: table, "
                                           r"start$"):
        Program([Pick("table"), Place("table", "shelf")]).validate(world)


def test_world_round_trip_and_validation():
    world = World.of(Landmark("box", [1.0, 0.5, 0.2]), Landmark("other_table", [3.0, 0.0, 0.4], "surface", 0.6))
    assert World.from_dict(world.to_dict()).to_dict() == world.to_dict()
    with pytest.raises(ProgramError, match="world.places.box.pos_w_m: must be 3 finite numbers"):
        World.from_dict({"box": {"pos_w_m": [1.0, float("nan"), 0.0]}})
    with pytest.raises(ProgramError, match="'start' is reserved"):
        World.from_dict({"start": {"pos_w_m": [0, 0, 0], "kind": "point"}})


def test_describe_is_one_line_per_step():
    text = EVERY_KIND.describe()
    lines = text.splitlines()
    assert lines[0] == "1. walk forward 2 m at 0.4 m/s"
    assert lines[4] == "5. turn right 90 deg at 17.2 deg/s"
    assert lines[19] == "20. walk to table, while: wave, crouch"
    assert lines[20:] == ["21. repeat 3 times:", "   21.1. walk forward 1 m", "   21.2. turn left 90 deg"]
    assert EVERY_KIND.count_primitives() == 20 + 6
