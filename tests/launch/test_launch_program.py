"""A behaviour program as a launch file's input: schema errors name the key; in MuJoCo a short
walk/turn program reaches its targets by ground truth."""

import math

import pytest
import yaml

from g1_control.errors import LaunchFileError
from g1_control.launch.schema import load_launch, parse_launch
from tests.paths import LAUNCH_DIR


def program_launch(input_section, **extra):
    data = yaml.safe_load((LAUNCH_DIR / "sim_program.yaml").read_text())
    data["input"] = {"type": "program", **input_section}
    data.update(extra)
    return data


def test_a_program_in_the_launch_file_validates_and_sizes_the_run():
    launch = parse_launch(program_launch({"program": [{"kind": "walk", "distance_m": 1.0},
                                                      {"kind": "turn", "angle_rad": 1.5708}]}))
    program = launch.input.parsed_program()
    assert [s.kind for s in program.steps] == ["walk", "turn"]
    # start delay + walk (2 x 1 m / 0.5 m/s + 5 s) + turn (2 x 90 deg / 0.6 rad/s + 5 s) + the end hold
    assert launch.total_duration_s == pytest.approx(1.0 + 9.0 + 2 * 1.5708 / 0.6 + 5.0 + 1.0, rel=1e-3)


def test_program_errors_name_the_key():
    with pytest.raises(LaunchFileError, match=r"input.program\[1\] \(walk\).distance_m: must be > 0; got -2"):
        parse_launch(program_launch({"program": [{"kind": "stand", "duration_s": 1.0},
                                                 {"kind": "walk", "distance_m": -2.0}]}))
    with pytest.raises(LaunchFileError, match=r"input.program\[0\].kind: unknown step kind 'jump'"):
        parse_launch(program_launch({"program": [{"kind": "jump"}]}))
    with pytest.raises(LaunchFileError, match=r"input.instruction: unknown word 'wlak'.*closest known words: walk"):
        parse_launch(program_launch({"instruction": "wlak forward 2 meters"}))
    with pytest.raises(LaunchFileError, match="needs `program` .* or `instruction`"):
        parse_launch(program_launch({}))
    with pytest.raises(LaunchFileError, match=r"input.program: step 1 \(walk\).target: 'door' is not in the world"):
        parse_launch(program_launch({"instruction": "walk to the door"}))
    with pytest.raises(LaunchFileError, match=r"input.places.door.kind: 'portal' is not one of"):
        parse_launch(program_launch({"instruction": "walk to the door",
                                     "places": {"door": {"pos_w_m": [3, 0, 0], "kind": "portal"}}}))
    with pytest.raises(LaunchFileError, match="input.program: only input.type program runs a program"):
        parse_launch({"name": "t", "input": {"type": "scripted", "timeline": [{"duration_s": 1.0}],
                                             "program": [{"kind": "stand", "duration_s": 1.0}]}})


def test_an_instruction_with_places_validates():
    launch = parse_launch(program_launch({"instruction": "walk to the door and wave",
                                          "places": {"door": {"pos_w_m": [3, 0, 0], "kind": "point"}}}))
    assert launch.input.parsed_program().steps[0].target == "door"


def test_two_step_program_reaches_its_targets_in_mujoco(tmp_path):
    """Walk 1 m, turn right 90 degrees: the runner steers by the estimator; ground truth judges."""
    from g1_control.launch.runner import run

    launch = load_launch(LAUNCH_DIR / "sim_program.yaml",
                         overrides=["input.program=[{kind: walk, distance_m: 1.0}, "
                                    "{kind: turn, angle_rad: 1.5708, direction: right}]"])
    result = run(launch, progress=False)
    assert not result.fell
    program = result.extra["program"]
    assert program["finished"] and program["pose"] == "estimator"
    walk, turn = program["steps"]
    print(f"\nwalk: {walk['verdict']['text']}; turn: {turn['verdict']['text']}")
    assert walk["status"] == turn["status"] == "completed"
    assert abs(walk["verdict"]["values"]["error_rel"]) <= 0.10
    assert abs(turn["verdict"]["values"]["error_rad"]) <= math.radians(10)
    assert walk["verdict"]["ok"] and turn["verdict"]["ok"]
    # the run ended with the program, not at its time budget
    assert result.duration_s < launch.total_duration_s - 5.0


def test_steps_the_robot_fell_in_are_missed_and_goal_steps_take_ground_truth():
    from g1_control.launch.runner import finish_program_verdicts
    from g1_control.program.device import StepRecord
    from g1_control.program.runner import StepOutcome
    from g1_control.program.steps import Pick, Stand, Turn
    from g1_control.report.verdict import Verdict

    def rec(step, t0, t1, goal_id=None):
        return StepRecord(StepOutcome("1", step.kind, step.describe(), "completed", t0, t1), step, goal_id=goal_id,
                          verdict=Verdict(True, "fine"))

    turn, pick, stand = rec(Turn(angle_rad=1.0), 0.0, 3.0), rec(Pick("box"), 3.0, 9.0, "g1"), rec(Stand(2.0), 9.0, 11.0)
    goals = [{"goal_id": "g1", "kind": "pick", "status": "reached", "box_rise_m": 0.01, "dropped": False}]
    finish_program_verdicts([turn, pick, stand], goals, {"t_s": 10.0, "kind": "tilt", "detail": "x"})
    assert turn.verdict.ok
    assert not pick.verdict.ok and "box lifted 1.0 cm" in pick.verdict.text, "the box barely rose"
    assert not stand.verdict.ok and "FELL at 10.00 s" in stand.verdict.text
