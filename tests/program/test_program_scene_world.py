"""Places a program may name in a launch file's scene (World.from_scene) and which launch runs it."""

import numpy as np
import pytest
import yaml

from g1_control.errors import LaunchFileError
from g1_control.launch.inputs import program_launch_name
from g1_control.launch.schema import load_launch, parse_launch
from g1_control.program import parse_instruction
from tests.paths import LAUNCH_DIR


def test_scene_tables_platforms_and_boxes_are_places():
    world = load_launch(LAUNCH_DIR / "sim_scene_program.yaml").program_world()
    assert set(world.names()) == {"table", "other_table", "platform", "box", "door", "start"}
    table, box = world.get("table"), world.get("box")
    assert table.kind == "surface" and np.allclose(table.pos_w_m, [2.25, 0.0, 0.7])
    assert table.stop_distance_m() == pytest.approx(0.4 + 0.3), "clear of the table's farthest edge"
    assert box.kind == "object" and box.pos_w_m[2] == pytest.approx(0.85)
    # the box stands 0.15 m inside the table's near edge: stop as far from the edge as from a box on the floor
    assert box.stop_distance_m() == pytest.approx(0.45 + 0.15)
    assert world.get("door").kind == "point"


def test_a_place_named_twice_is_refused_with_its_key():
    data = yaml.safe_load((LAUNCH_DIR / "sim_scene_program.yaml").read_text())
    data["input"]["places"]["table"] = {"pos_w_m": [1, 1, 0]}
    with pytest.raises(LaunchFileError, match="input.places.table: the scene already has a 'table'"):
        parse_launch(data)


def test_programs_with_places_or_goals_run_in_the_scene():
    assert program_launch_name(parse_instruction("walk forward 1 m and come back")) == "sim_program"
    assert program_launch_name(parse_instruction("walk to the door")) == "sim_scene_program"
    assert program_launch_name(parse_instruction("reach forward 20 cm")) == "sim_scene_program"
    assert program_launch_name(parse_instruction("walk forward 1 m while reaching forward 10 cm")) == \
        "sim_scene_program"
