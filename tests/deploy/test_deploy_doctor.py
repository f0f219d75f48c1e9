"""`g1 doctor`: the robot found (or not) on the network, every finding with its fix, nothing sent.

Against the robot emulator on lo (domain 1, a partition of its own), as `g1 sim-robot` runs it."""

from __future__ import annotations

import json

import pytest
from deploy_test_helpers import SIM2SIM

from g1_control.cli.main import main
from g1_control.deploy.doctor import ROWS, DoctorOptions, diagnose, healthy
from g1_control.deploy.preflight import DEBUG_MODE
from g1_control.launch.schema import load_launch


def _doctor(partition, **changes):
    launch = load_launch(SIM2SIM)
    for key, value in changes.items():
        setattr(launch.backend, key, value)
    options = DoctorOptions(partition=partition, listen_s=1.0)
    return {r.name: r for r in diagnose(launch, options, say=lambda _: None)}


def test_a_healthy_emulated_robot_is_found_checked_and_nothing_is_sent(partition, mock_robot):
    robot = mock_robot().start()
    rows = _doctor(partition)
    assert list(rows) == list(ROWS)
    assert {name: r.status for name, r in rows.items()} == {
        "interface": "pass", "state_stream": "pass", "variant": "pass", "peers": "pass", "imu_upright": "pass",
        "joint_limits": "pass", "temperatures": "pass", "motion_service": "pass"}
    assert rows["variant"].reason.startswith("mode_machine 5 (g1_29dof, 29 DoF)")
    assert rows["motion_service"].reason == ("built-in controller 'ai' active; g1 deploy will release it (ReleaseMode) "
                                             "before it sends anything")
    assert healthy(list(rows.values()))
    # It only asked: no LowCmd_ reached the robot, and the service saw CheckMode (1001) and nothing else.
    assert robot.endpoint.last_command is None
    assert robot.service.active_mode == "ai" and set(robot.service.calls) == {1001}


def test_no_robot_names_the_domains_tried_and_the_fix(partition):
    rows = _doctor(partition)
    assert rows["interface"].status == "pass"
    assert rows["state_stream"].status == "fail"
    assert rows["state_stream"].reason == ("no robot state (rt/lowstate) within 1.0 s on lo, DDS domains 1, 0: start "
                                           "the emulated robot first (g1 sim-robot, domain 1 on lo)")
    assert {rows[n].status for n in ROWS[2:]} == {"not run"}
    assert not healthy(list(rows.values()))


def test_a_robot_on_another_domain_is_found_there(partition, mock_robot):
    mock_robot().start()  # domain 1
    rows = _doctor(partition, domain=0)
    assert rows["state_stream"].status == "fail"
    assert rows["state_stream"].reason == ("no LowState_ on DDS domain 0, but a robot (mode_machine 5) publishes on "
                                           "domain 1: set backend.domain: 1 (or --domain 1)")


def test_a_second_writer_of_the_robots_commands_is_named(partition, mock_robot):
    from g1_control.hardware.links.dds import DdsLink

    mock_robot().start()
    other = DdsLink("host", "lo", 1, partition=partition)  # another program that commands this robot
    try:
        rows = _doctor(partition)
    finally:
        other.close()
    assert rows["peers"].status == "fail"
    assert "other writer(s) of rt/lowcmd on" in rows["peers"].reason and "stop it first" in rows["peers"].reason


def test_an_active_controller_without_release_asks_for_debug_mode(partition, mock_robot):
    mock_robot().start()
    rows = _doctor(partition, release_motion_service=False)
    assert rows["motion_service"].status == "fail"
    assert rows["motion_service"].reason == ("built-in controller 'ai' active and backend.release_motion_service is "
                                             "false: the robot would mix its own commands with ours. " + DEBUG_MODE)


def test_the_command_prints_the_table_writes_json_and_exits_1_on_a_finding(partition, tmp_path, capsys):
    out = tmp_path / "doctor.json"
    code = main(["doctor", "sim2sim", "--listen", "0.5", "--partition", partition, "--json", str(out)])
    assert code == 1
    text = capsys.readouterr().out
    assert "state_stream    FAIL" in text and "fix the rows marked FAIL" in text
    assert [r["name"] for r in json.loads(out.read_text())] == list(ROWS)


def test_interface_auto_without_a_nic_on_the_robot_network_says_how_to_add_one(partition, monkeypatch):
    import ipaddress

    from g1_control.hardware.links import network

    monkeypatch.setattr(network, "interface_table", lambda: {"lo": ipaddress.IPv4Interface("127.0.0.1/8"),
                                                              "eth0": ipaddress.IPv4Interface("10.0.0.5/24")})
    rows = _doctor(partition, interface="auto")
    assert rows["interface"].status == "fail"
    assert rows["interface"].reason.startswith(
        "--interface auto: no interface here has an address on the robot's network 192.168.123.0/24 (interfaces: "
        "lo 127.0.0.1/8, eth0 10.0.0.5/24). Cable the robot to this computer and give that NIC an address there")
    assert rows["state_stream"].reason == "not run: no usable interface"


@pytest.mark.parametrize("name", ["nonexistent0"])
def test_a_named_nic_off_the_robot_network_is_refused_with_the_fix(partition, name):
    rows = _doctor(partition, interface=name)
    assert rows["interface"].status == "fail"
    assert rows["state_stream"].status == "not run"
