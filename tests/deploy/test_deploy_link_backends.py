"""g1 deploy over the byte links (bench rigs, microcontroller bridges): the CAN transport on
python-can's virtual bus runs the whole preflight and state machine against a MockG1 endpoint;
serial ports are validated and opened. Rates are a bench rig's, not the robot's 500 Hz."""

from __future__ import annotations

import os
import uuid

import pytest
from deploy_test_helpers import ROOT, write_launch

from g1_control.deploy.backends import check_link_endpoint, open_robot_backend
from g1_control.deploy.session import DeployOptions, deploy
from g1_control.errors import TransportError
from g1_control.launch.schema import load_launch

pytestmark = pytest.mark.timing

BENCH = {"rates": {"lowlevel_hz": 50}, "backend": {"command_rate_hz": 100, "interface": None, "domain": 0,
                                                   "connect_timeout_s": 2.0},
         "deploy": {"min_state_rate_hz": 50, "state_window_s": 0.3, "input_check_s": 0.1, "exit_damping_s": 0.3},
         "input": {"type": "unitree_remote", "timeline": None, "device": {}}}


@pytest.fixture
def can_robot():
    """A MockG1 behind the robot side of a virtual CAN FD bus, 200 Hz LowState_."""
    from g1_control.hardware.links.can_bus import CanLink
    from g1_control.sim.emulator import FaultyPhysics
    from g1_control.sim.mock_robot import MockG1
    from g1_control.sim.robot_endpoint import RobotEndpoint

    channel = f"deploy-{os.getpid()}-{uuid.uuid4().hex[:6]}"
    link = CanLink("robot", interface="virtual", channel=channel)
    # FaultyPhysics also puts the (idle) remote's 40 bytes into every state, as the robot does.
    endpoint = RobotEndpoint(link, FaultyPhysics(MockG1()), rate_hz=200.0).start()
    yield channel, endpoint
    endpoint.stop()
    link.close()


def test_deploy_over_can_runs_preflight_and_the_state_machine(tmp_path, can_robot):
    channel, endpoint = can_robot
    # The MockG1 hangs on a gantry (its base never moves) while sim2sim's walking policy swings its legs:
    # the pelvis height the estimator reads off the leg kinematics is then a folded leg's, not a fall's
    # (0.26 m, 0.8 s into control, in one CI run: "fall: pelvis at 0.26 m"). Only the tilt judges a fall here.
    path = write_launch(tmp_path, {**BENCH, "backend": {**BENCH["backend"], "type": "can",
                                                        "can_interface": "virtual", "channel": channel},
                                   "fall": {"min_pelvis_height_m": 0.01}})
    lines: list[str] = []
    report = deploy(path, DeployOptions(yes=True, duration_s=1.0), say=lines.append)
    text = "\n".join(lines)
    status = {r["name"]: r["status"] for r in report.preflight}
    assert status["interface"] == "pass" and "virtual bus" in text
    assert status["state_stream"] == "pass" and status["variant"] == "pass" and status["estop_input"] == "pass", text
    assert report.sequence == ["zero_torque", "ramp", "hold", "control", "damping"]
    assert report.end_reason.startswith("control time over") and not report.fault
    last = endpoint.last_command
    assert float(last.motor_kp_nm_per_rad.max()) == 0.0 and float(last.motor_kd_nms_per_rad[0]) > 0.0
    assert endpoint.counters.bad_crc == 0 and endpoint.counters.commands_applied > 100
    # A command lives safety.command_hold_ticks (3) tracker ticks on the link before its hold form takes over.
    assert report.link["command_ttl_s"] == pytest.approx(3 / 50)


def test_missing_socketcan_interface_and_serial_port_are_refused(tmp_path):
    can = load_launch(write_launch(tmp_path, {"backend": {"type": "can", "can_interface": "socketcan",
                                                          "channel": "can7"}}, "can.yaml"))
    with pytest.raises(TransportError, match="CAN network interface 'can7' does not exist; interfaces here: "):
        check_link_endpoint(can.backend)
    serial = load_launch(write_launch(tmp_path, {"backend": {"type": "serial", "port": "/dev/ttyUSB97"}},
                                      "serial.yaml"))
    with pytest.raises(TransportError, match="serial port '/dev/ttyUSB97' does not exist; plug in the bridge or fix "
                                             "backend.port"):
        check_link_endpoint(serial.backend)


def test_serial_backend_opens_on_a_pty(tmp_path):
    from g1_control.hardware.links.serial_port import open_pty_pair

    tty_end, master_end = open_pty_pair()
    try:
        launch = load_launch(write_launch(tmp_path, {"backend": {"type": "serial", "port": tty_end.name}}))
        assert check_link_endpoint(launch.backend) == f"serial port {tty_end.name} exists and is accessible"
        backend = open_robot_backend(launch.backend)
        try:
            assert backend.link.describe() == f"serial ({tty_end.name})"
            assert backend.expected_mode_machine == 5 and backend.command_period_s == pytest.approx(0.002)
        finally:
            backend.close()
    finally:
        tty_end.close()
        master_end.close()


def test_a_commands_life_on_the_link_is_safety_command_hold_ticks_tracker_ticks():
    from g1_control.deploy.backends import command_ttl_s

    assert command_ttl_s(load_launch(ROOT / "launch/sim2sim_wbc.yaml")) == pytest.approx(3 / 100)  # the WBC at 100 Hz
    assert command_ttl_s(load_launch(ROOT / "launch/robot.yaml")) == pytest.approx(3 / 50)
    assert command_ttl_s(load_launch(ROOT / "launch/sim2sim_wbc.yaml", ["safety.command_hold_ticks=5"])) == pytest.approx(0.05)
    assert command_ttl_s(load_launch(ROOT / "launch/sim2sim_wbc.yaml", ["safety.command_hold_ticks=0"])) is None
