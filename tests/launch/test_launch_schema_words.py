"""Refusals of the estimation, simulator, push, battery, hands and reference-parameter checks word for
word, and the values at their limits accepted (issue 26: the mutation run's schema group). Each
refusal names the key and what would make it right; each boundary the docs give holds."""

from __future__ import annotations

import math

import pytest

from g1_control.errors import LaunchFileError
from g1_control.launch.schema import PushConfig, parse_launch
from g1_control.robot import g1
from tests.launch.launch_schema_data import DDS, assert_holds, launch_data

PUSH = {"at_s": 0.5, "force_h_n": [0.0, 50.0, 0.0]}
LO = {"interface": "lo"}


def _refused(sections: dict) -> str:
    with pytest.raises(LaunchFileError) as info:
        parse_launch(launch_data("words", **sections))
    return str(info.value).removeprefix("<launch>: ")


@pytest.mark.parametrize("sections, message", [
    ({"backend": DDS, "estimation": {"steer_by": "ground_truth"}},
     "estimation.steer_by: ground_truth needs a simulator's ground truth; backend.type unitree_dds drives a robot, "
     "which reports none (use auto or estimate)"),
    ({"estimation": {"perception": LO}},
     "estimation.perception: objects are placed with the robot's estimate, which this MuJoCo run does not steer by "
     "(steer_by auto: ground truth); set estimation.steer_by: estimate to use it"),
    ({"estimation": {"steer_by": "ground_truth", "external_pose": LO}},
     "estimation.external_pose: the external pose is fused into the robot's estimate, which this MuJoCo run does not "
     "steer by (steer_by ground_truth: ground truth); set estimation.steer_by: estimate to use it"),
    ({"backend": {"simulator": "nope"}},
     "backend.simulator: 'nope' is not a simulator profile; known: unitree_mujoco (leave it out for a robot)"),
    ({"backend": {"simulator": "unitree_mujoco"}},
     "backend.simulator: unitree_mujoco is allowed on loopback only (type unitree_dds, interface lo); got type "
     "mujoco, interface None: a robot must fill crc, tick and mode_machine, and is checked for them"),
    ({"backend": {**DDS, "interface": "eth0", "simulator": "unitree_mujoco"}},
     "backend.simulator: unitree_mujoco is allowed on loopback only (type unitree_dds, interface lo); got type "
     "unitree_dds, interface eth0: a robot must fill crc, tick and mode_machine, and is checked for them"),
    ({"backend": {"hands": "dex3", "expected_variant": "g1_23dof"}},
     "backend.hands: Dex3 hands are modelled on the 29-DoF G1 only; expected_variant is g1_23dof"),
    ({"deploy": {"min_battery_v": g1.BATTERY_EMPTY_V}},
     f"deploy.min_battery_v: {g1.BATTERY_EMPTY_V} V is outside the G1 battery's range ({g1.BATTERY_EMPTY_V} V empty, "
     f"{g1.BATTERY_FULL_V} V full); the check could never fire (the pack is never that low)"),
    ({"deploy": {"min_battery_v": g1.BATTERY_FULL_V}},
     f"deploy.min_battery_v: {g1.BATTERY_FULL_V} V is outside the G1 battery's range ({g1.BATTERY_EMPTY_V} V empty, "
     f"{g1.BATTERY_FULL_V} V full); the check could never pass (the pack is never that high)"),
    ({"input": {"type": "ros2", "device": {"bogus": 1}}},
     "input.device.bogus is not a setting of a ros2 input; known: interface, domain, cmd_vel, stale_after_s, "
     "publish_hz, partition"),
    ({"backend": DDS, "pushes": [PUSH]}, "pushes: only a simulated run (backend.type mujoco) can be pushed"),
    ({"pushes": [{**PUSH, "at_s": -0.1}]},
     "pushes[0]: at_s must be >= 0 and duration_s in (0, 2] s; got at_s -0.1, duration_s 0.2"),
    ({"pushes": [{**PUSH, "duration_s": 0.0}]},
     "pushes[0]: at_s must be >= 0 and duration_s in (0, 2] s; got at_s 0.5, duration_s 0.0"),
    ({"pushes": [{**PUSH, "duration_s": 2.5}]},
     "pushes[0]: at_s must be >= 0 and duration_s in (0, 2] s; got at_s 0.5, duration_s 2.5"),
    ({"limits": {"max_tilt_rad": math.pi}},
     "limits.max_tilt_rad: 3.141592653589793 rad must be below pi (3.1416): no tilt exceeds pi, so the fall could "
     "never be detected"),
    ({"generator": {"type": "scripted", "reference": "stand", "reference_params": {"variant": 1.0}}},
     "generator.reference_params: variant not a parameter of reference 'stand'; known: duration_s"),
])
def test_refusals_word_for_word(sections, message):
    assert _refused(sections) == message


@pytest.mark.parametrize("sections", [
    {"estimation": {"steer_by": "ground_truth"}},  # MuJoCo has ground truth
    {"estimation": {"steer_by": "estimate", "external_pose": LO, "perception": LO}},
    {"backend": DDS, "estimation": {"external_pose": LO, "perception": LO}},  # auto on a robot: the estimate
    {"backend": {**DDS, "simulator": "unitree_mujoco"}},
    {"pushes": [{**PUSH, "at_s": 0.0, "duration_s": 2.0}, {**PUSH, "duration_s": 1e-9}]},
    {"deploy": {"max_start_temperature_c": g1.MOTOR_MAX_TEMPERATURE_C}},
    {"deploy": {"min_battery_v": math.nextafter(g1.BATTERY_EMPTY_V, math.inf)}},
    {"deploy": {"min_battery_v": math.nextafter(g1.BATTERY_FULL_V, 0.0)}},
    {"limits": {"max_tilt_rad": math.nextafter(math.pi, 0.0)}},
    {"backend": {"hands": "dex3", "expected_variant": "g1_29dof"}},
])
def test_values_at_their_limits_are_accepted_as_given(sections):
    data = launch_data("limits", **sections)
    assert_holds(parse_launch(data), data)


def test_a_push_built_in_code_with_two_force_components_is_refused_naming_the_key():
    """A bench builds its pushes in code, past the YAML reader's item count."""
    with pytest.raises(LaunchFileError) as info:
        PushConfig(at_s=0.5, force_h_n=(0.0, 50.0)).validate("pushes[3]")  # type: ignore[arg-type]
    assert str(info.value) == "pushes[3].force_h_n: need 3 numbers (x forward, y left, z up), got (0.0, 50.0)"
