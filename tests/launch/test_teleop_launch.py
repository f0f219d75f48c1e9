"""Teleop through launch files: a scripted gamepad session through the real evdev reader drives
the simulated robot; e-stop and a lost pad end in damping via the safety layer."""

from pathlib import Path

import numpy as np
import pytest

from g1_control.errors import LaunchFileError
from g1_control.launch import runner
from g1_control.launch.builder import build_loop, command_limits, make_tracker
from g1_control.launch.schema import load_launch, parse_launch
from g1_control.report.overlay import overlay_lines

REPO = Path(__file__).resolve().parents[2]


def demo(script, duration):
    launch = load_launch(REPO / "launch" / "sim_gamepad_demo.yaml")
    launch.input.gamepad_script = script
    launch.duration_s = duration
    return launch


def test_gamepad_script_walks_the_robot_forward():
    launch = demo([{"t_s": 0.5, "axes": {"left_y": -1.0}}], 7.0)  # full stick forward, RT released: 50 %
    result = runner.run(launch, progress=False)
    assert not result.fell
    held = [s for s in result.segments if s.commanded[0] > 0]
    # The stick scales to what the tracker delivers (its measured envelope), not to 1 m/s.
    top = command_limits(launch, make_tracker(launch).command_limits).vx_mps[1]
    assert top < 1.0
    assert held and held[-1].commanded[0] == pytest.approx(0.5 * top)
    assert abs(held[-1].error_pct()[0]) < 10


def test_gamepad_estop_chord_damps():
    launch = demo([{"t_s": 0.5, "axes": {"left_y": -0.6}}, {"t_s": 2.0, "press": ["LB", "RB"]}], 3.0)
    loop = build_loop(launch)
    loop.reset()
    loop.run(3.0)
    assert loop.safety.trip_event.kind.value == "estop"
    assert 2.0 <= loop.safety.trip_event.t_s < 2.05
    assert np.all(loop.motor_command.kp == 0)
    labels, values = overlay_lines(loop)
    assert "safety" in labels and "DAMPING (estop)" in values
    loop.input.close()


def test_unplugged_gamepad_stops_then_damps():
    launch = demo([{"t_s": 0.2, "axes": {"left_y": -1.0}}], 10.0)
    loop = build_loop(launch)
    loop.reset()
    loop.run(2.0)
    assert loop.command.vx_mps > 0.3  # 50 % of the tracker's envelope (0.65 m/s)
    loop.input.feeder.unplug()
    loop.run(0.5)
    assert loop.input.lost and loop.command.vx_mps == 0.0 and not loop.faulted
    loop.run(1.0)
    assert loop.faulted and loop.safety.trip_event.kind.value == "input_lost"
    loop.input.close()


def test_bad_device_settings_are_refused_at_validation():
    base = {"name": "t", "input": {"type": "gamepad_script", "gamepad_script": [{"t_s": 0.0}]}}
    base["input"]["device"] = {"mapping": {"buttons": {"A": "run", "LB": "run2"}}}
    with pytest.raises(LaunchFileError, match="input.device.mapping.buttons.LB"):
        parse_launch(base)
    base["input"]["device"] = {}
    base["input"]["gamepad_script"] = [{"t_s": 1.0, "press": ["Z"]}]
    with pytest.raises(LaunchFileError, match=r"input.gamepad_script\[0\].press: 'Z' is not a gamepad button"):
        parse_launch(base)


def test_missing_gamepad_path_is_a_clear_error_and_nothing_runs(tmp_path, capsys):
    from g1_control.cli.main import main

    bad = tmp_path / "badpad.yaml"
    bad.write_text(f"name: badpad\ninput:\n  type: gamepad\n  device: {{path: /dev/input/event99}}\n"
                   f"output: {{dir: {tmp_path / 'runs'}}}\n")
    assert main(["launch", str(bad), "--no-video", "--quiet"]) == 1
    assert "input.device.path: gamepad device '/dev/input/event99' does not exist" in capsys.readouterr().err
    assert not (tmp_path / "runs").exists()
