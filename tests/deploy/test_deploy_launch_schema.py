"""Launch-file sections for the robot path: robot backends, safety, deploy; each mistake refused
with the key path and what to do."""

from __future__ import annotations

import pytest
from deploy_test_helpers import write_launch

from g1_control.errors import LaunchFileError
from g1_control.launch.schema import load_launch


def test_shipped_robot_launch_files_validate():
    from deploy_test_helpers import ROOT

    robot = load_launch(ROOT / "launch" / "robot.yaml")
    assert robot.backend.type == "unitree_dds" and robot.backend.domain == 0
    assert robot.input.type == "unitree_remote" and robot.safety.stale_state_s == 0.05
    sim2sim = load_launch(ROOT / "launch" / "sim2sim.yaml")
    assert (sim2sim.backend.interface, sim2sim.backend.domain) == ("lo", 1)
    assert sim2sim.safety.stale_state_s == 0.25 and sim2sim.deploy.ramp_s == 2.0


@pytest.mark.parametrize("changes, message", [
    ({"backend": {"interface": None}}, "backend.interface: a unitree_dds backend must name its network interface"),
    ({"backend": {"domain": 300}}, "backend.domain: 300 is not a DDS domain id"),
    ({"backend": {"expected_variant": "g1_27dof"}}, "backend.expected_variant: expected one of"),
    ({"backend": {"command_rate_hz": 5000}}, "backend.command_rate_hz: 5000.0 is outside"),
    ({"backend": {"type": "can"}}, "backend: a can backend needs can_interface and channel"),
    ({"backend": {"type": "serial"}}, "backend.port: a serial backend needs the port"),
    ({"deploy": {"ramp_s": 1.0}}, "deploy.ramp_s: 1.0 s is too fast; ramp to the default pose over at least 2 s"),
    ({"deploy": {"dry_run_s": 3}}, "deploy.dry_run_s: 3.0 s; the simulated dry run lasts at least 10 s"),
    ({"deploy": {"ramp": 3}}, "deploy: unknown key 'ramp'"),
    ({"safety": {"stale_state_s": -1}}, "safety: SafetyConfig.stale_state_s is -1.0; it must not be negative"),
    ({"safety": {"stale_state_s": "soon"}}, "safety.stale_state_s: expected a number, got 'soon'"),
])
def test_robot_sections_refuse_mistakes(tmp_path, changes, message):
    path = write_launch(tmp_path, changes)
    with pytest.raises(LaunchFileError) as info:
        load_launch(path)
    assert message in str(info.value)
    assert str(path) in str(info.value)


def test_can_and_serial_backends_validate(tmp_path):
    can = load_launch(write_launch(tmp_path, {"backend": {"type": "can", "can_interface": "virtual",
                                                          "channel": "bench", "interface": None}}, "can.yaml"))
    assert (can.backend.can_interface, can.backend.channel, can.backend.can_fd) == ("virtual", "bench", True)
    serial = load_launch(write_launch(tmp_path, {"backend": {"type": "serial", "port": "/dev/ttyUSB0",
                                                             "baudrate": 2000000}}, "serial.yaml"))
    assert serial.backend.port == "/dev/ttyUSB0" and serial.backend.baudrate == 2000000


def test_g1_launch_refuses_a_robot_launch_file():
    from deploy_test_helpers import SIM2SIM

    from g1_control.launch.runner import run

    with pytest.raises(LaunchFileError, match="drives a robot .*run it with `g1 deploy`"):
        run(load_launch(SIM2SIM), progress=False)
