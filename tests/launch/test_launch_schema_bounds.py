"""The launch schema's limits are inclusive where it says so: every boundary value it documents is
accepted (the malformed corpus shows the values just past them refused)."""

from __future__ import annotations

import pytest

from g1_control.launch.schema import parse_launch
from tests.launch.launch_schema_data import DDS, assert_holds, launch_data


def _with(**sections) -> dict:
    return launch_data("bounds", **sections)


@pytest.mark.parametrize("sections", [
    {"backend": {"physics_dt_s": 0.0005}}, {"backend": {"physics_dt_s": 0.005}},
    {"backend": {**DDS, "domain": 0}}, {"backend": {**DDS, "domain": 232}},
    {"backend": {**DDS, "command_rate_hz": 50.0}}, {"backend": {**DDS, "command_rate_hz": 1000.0}},
    {"backend": {**DDS, "mode_pr": 1}}, {"backend": {**DDS, "connect_timeout_s": 0.001}},
    {"backend": {"type": "can", "can_interface": "virtual", "channel": "bus0"}},
    {"backend": {"type": "serial", "port": "loop://"}},
    {"deploy": {"ramp_s": 2.0, "dry_run_s": 10.0}},
    {"deploy": {"auto_start_s": 0.0, "auto_run_s": 0.0, "min_hold_s": 0.0, "exit_damping_s": 0.0}},
    {"deploy": {"state_window_s": 0.001, "input_check_s": 0.001, "joint_limit_tolerance_rad": 0.0}},
    {"deploy": {"min_state_rate_hz": 0.001, "max_start_tilt_rad": 0.001}},
    {"deploy": {"realtime_priority": 0}}, {"deploy": {"realtime_priority": 99}},
    {"rates": {"lowlevel_hz": 10000, "tracker_hz": 50, "input_hz": 100, "estimator_hz": 100}},
    {"limits": {"max_vx_mps": 0.001, "max_vy_mps": 0.001, "max_wz_radps": 0.001, "max_tilt_rad": 0.001}},
    {"input": {"type": "scripted", "timeline": [{"duration_s": 1.0, "vx_mps": -1.0, "vy_mps": 0.6, "wz_radps": -1.0}]}},
    {"rates": {"tracker_hz": 250}, "tracker": {"type": "wbc"}, "generator": {"type": "scripted", "reference": "stand"}},
    {"rates": {"tracker_hz": 250}, "tracker": {"type": "wbc"},
     "generator": {"type": "scripted", "reference": "walk", "reference_params": {"speed_mps": 0.3}}},
    {"tracker": {"type": "wbt"}},
    {"rates": {"tracker_hz": 250}, "tracker": {"type": "wbc"}, "generator": {"type": "scripted"}},
    {"rates": {"lowlevel_hz": 1000, "tracker_hz": 200}, "tracker": {"type": "wbc"}, "generator": {"type": "scripted"}},
    # robot-link settings are not checked for the simulator, which does not use them
    {"backend": {"type": "mujoco", "command_rate_hz": 10.0, "mode_pr": 7, "connect_timeout_s": 0.0}},
    # each device's mapping is checked against its own layout
    {"input": {"type": "unitree_remote", "device": {"mapping": {"buttons": {"L1+R1": "estop", "B": "stop"}}}}},
    {"input": {"type": "gamepad", "device": {"mapping": {"buttons": {"LB+RB": "estop"}}}}},
    {"input": {"type": "random", "random": {"style": "wave"}}},
    {"duration_s": 0.001},
    {"backend": {"randomize": {"seed": 0, "mass_scale": [0.5, 2.0], "com_offset_m": 0.0, "motor_strength": [0.3, 1.2],
                               "latency_s": [0.0, 0.1], "foot_friction": [0.05, 3.0]}}},
    {"backend": {"randomize": {"seed": 7, "mass_scale": [1.0, 1.0], "com_offset_m": 0.1, "motor_strength": [1.0, 1.0],
                               "latency_s": [0.01, 0.01], "foot_friction": [0.8, 0.8]}}},
])
def test_boundary_values_are_accepted(sections):
    """Accepted, and held as given (a schema that clamped or replaced a boundary value would show)."""
    data = _with(**sections)
    assert_holds(parse_launch(data), data)


def test_total_duration_follows_the_input():
    assert parse_launch(_with(duration_s=5.0)).total_duration_s == 5.0
    two = {"type": "scripted", "timeline": [{"duration_s": 1.5}, {"duration_s": 2.5}]}
    assert parse_launch(_with(input=two)).total_duration_s == 4.0
    script = {"type": "gamepad_script", "gamepad_script": [{"t_s": 0.0, "press": "A"}, {"t_s": 4.0, "release": "A"}]}
    assert parse_launch(_with(input=script)).total_duration_s == 7.0
    assert parse_launch(_with(input={"type": "random"})).total_duration_s == 60.0


def test_a_missing_launch_file_is_named(tmp_path):
    from g1_control.errors import LaunchFileError
    from g1_control.launch.schema import load_launch

    with pytest.raises(LaunchFileError) as info:
        load_launch(tmp_path / "nope.yaml")
    assert str(info.value) == f"{tmp_path / 'nope.yaml'}: no such launch file"
