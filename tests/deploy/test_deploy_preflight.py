"""The preflight checklist over real DDS on loopback (lo, domain 1, a partition per test) against
emulated robots: a healthy one passes; each kind of bad input is refused with a message saying
what to do, and nothing is ever sent to the robot."""

from __future__ import annotations

import logging
import threading
import time

import numpy as np
import pytest
import yaml
from deploy_test_helpers import FAST, preflight_only, write_launch

from g1_control.cli.main import main
from g1_control.robot import g1

pytestmark = pytest.mark.timing


def _status(report) -> dict[str, str]:
    return {r["name"]: ("overridden" if r["overridden"] else r["status"]) for r in report.preflight}


def _reason(report, name: str) -> str:
    return next(r["reason"] for r in report.preflight if r["name"] == name)


def test_healthy_emulated_robot_passes_and_nothing_is_sent(tmp_path, partition, mock_robot):
    robot = mock_robot().start()
    report, refused, text = preflight_only(write_launch(tmp_path, FAST), partition)
    assert refused is None, text
    status = _status(report)
    assert status.pop("battery") == "skip" and set(status.values()) == {"pass"}, text
    assert "state_stream    PASS" in text and "dry_run         PASS        no fall" in text
    assert "motion_service  PASS        built-in controller 'ai' active; g1 deploy will release it" in text
    assert robot.endpoint.counters.commands_applied == 0 and robot.endpoint.counters.ignored_while_builtin_active == 0
    assert robot.service.active_mode == "ai", "a preflight never releases the built-in controller"


def test_wrong_interface_name_is_refused_before_any_dds(tmp_path, partition):
    report, refused, _ = preflight_only(write_launch(tmp_path, FAST), partition, interface="nonexistent0")
    assert refused is not None
    assert _status(report)["interface"] == "fail"
    assert "network interface 'nonexistent0' does not exist; interfaces here: " in _reason(report, "interface")
    assert "Use 'lo' for simulation, or the NIC cabled to the robot" in _reason(report, "interface")
    assert _status(report)["state_stream"] == "not run"


def test_no_robot_times_out_and_cannot_be_overridden(tmp_path, partition):
    path = write_launch(tmp_path, {**FAST, "backend": {"connect_timeout_s": 0.5}})
    report, refused, _ = preflight_only(path, partition, overrides=frozenset({"state_stream"}))
    assert refused is not None
    reason = _reason(report, "state_stream")
    assert reason.startswith("no valid LowState from the robot within 0.5 s on DDS (interface lo, domain 1")
    assert "check that the robot is on and cabled to this interface" in reason
    assert "--override state_stream refused: this failure cannot be overridden" in reason
    assert _status(report)["variant"] == "not run"
    assert "preflight failed (" in str(refused) and "nothing was sent to the robot" in str(refused)


def test_robot_of_another_dof_variant_is_refused(tmp_path, partition, mock_robot):
    mock_robot(mode_machine=4).start()
    report, refused, _ = preflight_only(write_launch(tmp_path, FAST), partition, overrides=frozenset({"variant"}))
    assert refused is not None and _status(report)["variant"] == "fail"
    assert _reason(report, "variant").startswith(
        "the robot reports mode_machine 4 (g1_23dof, 23 DoF) but the launch file expects g1_29dof and the policy is "
        "for g1_29dof; use a launch file and policy made for this robot")


def test_policy_for_another_robot_is_refused(tmp_path, partition, mock_robot):
    from g1_control.trackers.policy_spec import resolve_spec_path

    spec = yaml.safe_load(resolve_spec_path("holosoma_loco_ppo").read_text())
    spec["variant"] = "g1_23dof"
    (tmp_path / "other.yaml").write_text(yaml.safe_dump(spec))
    mock_robot().start()
    path = write_launch(tmp_path, {**FAST, "tracker": {"policy": str(tmp_path / "other.yaml")}})
    report, refused, _ = preflight_only(path, partition)
    assert refused is not None and _status(report)["policy"] == "fail"
    assert "is for the g1_23dof G1 but backend.expected_variant is g1_29dof; use a policy made for this robot" \
        in _reason(report, "policy")
    assert _status(report)["dry_run"] == "not run"


def test_corrupted_crcs_are_refused(tmp_path, partition, mock_robot):
    robot = mock_robot()
    robot.endpoint.corrupt_state_crc = True
    robot.start()
    path = write_launch(tmp_path, {**FAST, "backend": {"connect_timeout_s": 0.5}})
    report, refused, _ = preflight_only(path, partition)
    reason = _reason(report, "state_stream")
    assert refused is not None
    assert "no valid LowState from the robot within 0.5 s" in reason and "samples had a bad CRC" in reason


def test_intermittent_bad_crcs_fail_the_stream_check(tmp_path, partition, mock_robot):
    robot = mock_robot().start()
    stop = threading.Event()

    def flicker():  # ~2 samples in 25 corrupted: the stream arrives, but not clean
        while not stop.wait(0.05):
            robot.endpoint.corrupt_state_crc = True
            time.sleep(0.004)
            robot.endpoint.corrupt_state_crc = False

    thread = threading.Thread(target=flicker, daemon=True)
    thread.start()
    try:
        report, refused, _ = preflight_only(write_launch(tmp_path, FAST), partition)
    finally:
        stop.set()
        thread.join()
    assert refused is not None and _status(report)["state_stream"] == "fail"
    reason = _reason(report, "state_stream")
    assert " bad CRC" in reason and "corrupted samples on DDS" in reason and "check the cable, the switch" in reason


def test_short_samples_are_refused(tmp_path, partition, mock_robot):
    from g1_control.hardware.unitree.messages import LowState

    robot = mock_robot()
    robot.endpoint.publish = False
    stop = threading.Event()

    def send_short():
        short = LowState(mode_machine=5, tick=1).to_dds()[:600]
        while not stop.wait(0.002):
            robot.link.send(short)

    thread = threading.Thread(target=send_short, daemon=True)
    thread.start()
    try:
        path = write_launch(tmp_path, {**FAST, "backend": {"connect_timeout_s": 0.5}})
        report, refused, _ = preflight_only(path, partition)
    finally:
        stop.set()
        thread.join()
    assert refused is not None
    assert "were malformed" in _reason(report, "state_stream")


def test_hot_tilted_robot_with_a_joint_past_its_limit_is_refused_then_overridden_loudly(
        tmp_path, partition, mock_robot, caplog):
    robot = mock_robot(temperature_c=80.0)
    mock = robot.physics.inner
    knee = g1.JOINT_INDEX["left_knee_joint"]
    mock._q[knee] = 3.1
    mock.imu_quat_wxyz = np.array([np.cos(0.25), np.sin(0.25), 0.0, 0.0])  # 0.5 rad roll
    robot.start()
    path = write_launch(tmp_path, FAST)
    report, refused, _ = preflight_only(path, partition)
    assert refused is not None
    status = _status(report)
    assert (status["temperatures"], status["imu_upright"], status["joint_limits"]) == ("fail",) * 3
    assert _reason(report, "temperatures").endswith("motor at 80 °C (limit 70 °C): let the motors cool down")
    assert _reason(report, "imu_upright").startswith("tilt 0.500 rad > 0.30: stand the robot up or hang it")
    assert _reason(report, "joint_limits").startswith("1 joints outside their limits: left_knee_joint +3.100 rad")
    assert "override a check you have verified yourself with --override NAME (overridable here: imu_upright, " \
           "joint_limits, temperatures)" in str(refused)

    caplog.set_level(logging.ERROR, logger="g1_control.deploy")
    overrides = frozenset({"temperatures", "imu_upright", "joint_limits"})
    report, refused, text = preflight_only(path, partition, overrides=overrides)
    assert refused is None, text
    assert {n for n, s in _status(report).items() if s == "overridden"} == overrides
    assert "temperatures    OVERRIDDEN" in text
    assert "!!! WARNING: preflight check 'temperatures' FAILED and was OVERRIDDEN" in text
    assert sum("PREFLIGHT OVERRIDE" in r.message for r in caplog.records) == 3


def test_an_input_device_that_cannot_open_is_refused(tmp_path, partition, mock_robot):
    mock_robot().start()
    not_a_tty = tmp_path / "not-a-terminal"
    not_a_tty.write_text("")
    path = write_launch(tmp_path, {**FAST, "input": {"type": "keyboard", "timeline": None,
                                                      "device": {"path": str(not_a_tty)}}})
    report, refused, _ = preflight_only(path, partition, overrides=frozenset({"estop_input"}))
    assert refused is not None and _status(report)["estop_input"] == "fail"
    assert _reason(report, "estop_input").startswith("keyboard cannot be opened: ")
    assert "cannot be overridden" in _reason(report, "estop_input")


def test_scripted_input_off_loopback_has_no_estop(tmp_path):
    from g1_control.deploy.preflight import Preflight
    from g1_control.launch.schema import load_launch

    launch = load_launch(write_launch(tmp_path, {"backend": {"interface": "eth9"}}))
    pf = Preflight()
    assert not pf.check_input(None, launch)
    assert pf.results["estop_input"].reason == ("input.type scripted has no operator e-stop; a robot needs "
                                                "unitree_remote, gamepad or keyboard")


def test_cli_prints_the_table_and_exits_1_when_refused(tmp_path, partition, capsys):
    path = write_launch(tmp_path, {**FAST, "backend": {"connect_timeout_s": 0.3}})
    code = main(["deploy", str(path), "--partition", partition, "--preflight-only", "--json",
                 str(tmp_path / "report.json")])
    out, err = capsys.readouterr()
    assert code == 1
    assert "check           result      reason" in out and "state_stream    FAIL" in out
    assert "g1 deploy: error: preflight failed (" in err
    assert '"refused": true' in (tmp_path / "report.json").read_text()


def test_unknown_override_name_is_refused():
    from g1_control.deploy.preflight import Preflight
    from g1_control.errors import G1ControlError

    with pytest.raises(G1ControlError, match="--override temperature: no such check; checks: launch_file, "):
        Preflight(frozenset({"temperature"}))


def test_a_dry_run_that_falls_refuses(tmp_path):
    """A fall in the simulated dry run (here: a tilt limit no walking robot can keep) fails the check."""
    from g1_control.deploy.preflight import Preflight
    from g1_control.launch.schema import load_launch

    launch = load_launch(write_launch(tmp_path, {"limits": {"max_tilt_rad": 0.01}}))
    pf = Preflight()
    assert not pf.check_dry_run(launch)
    reason = pf.results["dry_run"].reason
    assert reason.startswith("FELL in simulation at ") and reason.endswith("do not run this policy/launch file on "
                                                                         "the robot")
    assert pf.dry_run.fell


def test_robot_launch_file_takes_the_one_nic_on_the_robot_network(tmp_path, partition, mock_robot, monkeypatch):
    """launch/robot.yaml's `interface: auto` never guesses: with no NIC on 192.168.123.0/24 it refuses and says
    how to add one; pointed at an emulated robot on lo it passes."""
    import ipaddress

    from deploy_test_helpers import ROOT

    from g1_control.hardware.links import network

    monkeypatch.setattr(network, "interface_table", lambda: {"lo": ipaddress.IPv4Interface("127.0.0.1/8")})
    report, refused, _ = preflight_only(ROOT / "launch" / "robot.yaml", partition)
    assert refused is not None
    assert _reason(report, "interface").startswith("--interface auto: no interface here has an address on the "
                                                   "robot's network 192.168.123.0/24 (interfaces: lo 127.0.0.1/8)")
    mock_robot().start()
    fast = write_launch(tmp_path, FAST, base=ROOT / "launch" / "robot.yaml")
    report, refused, text = preflight_only(fast, partition, interface="lo", domain=1)
    assert refused is None, text
    assert _reason(report, "estop_input") == "unitree_remote answering; e-stop on L1+R1"


def test_yes_is_refused_off_loopback(tmp_path, partition):
    report, refused, _ = preflight_only(write_launch(tmp_path, FAST), partition, interface="eth9", yes=True)
    assert refused is not None and _status(report)["interface"] == "not run"
    assert "--yes answers start and run with nobody watching; it is only for g1 sim-robot on 'lo'" \
        in _reason(report, "launch_file")


def test_yes_is_refused_on_a_can_bus_that_is_not_virtual(tmp_path, partition):
    """A socketcan bus reaches a robot: --yes (nobody presses start and run) is refused there as off lo;
    only the virtual bus counts as simulated."""
    can = {**FAST, "backend": {**FAST["backend"], "type": "can", "can_interface": "socketcan", "channel": "can0"}}
    report, refused, _ = preflight_only(write_launch(tmp_path, can), partition, yes=True)
    assert refused is not None and _status(report)["interface"] == "not run"
    assert "--yes answers start and run with nobody watching" in _reason(report, "launch_file")


def test_the_motion_service_is_asked_in_the_preflight_and_a_release_that_would_fail_is_refused(
        tmp_path, partition, mock_robot):
    """The release of the built-in controller is a preflight row, asked with CheckMode only: a robot whose
    service does not answer (debug mode already, or no service) with backend.release_motion_service true
    is refused before anything moves, with the fix; with the release off it is debug mode, not a fault.
    An active controller with the release off is refused (it would fight our commands), overrides or not."""
    robot = mock_robot().start()
    path = write_launch(tmp_path, FAST)
    report, refused, _ = preflight_only(path, partition, release_motion_service=False,
                                        overrides=frozenset({"motion_service"}))
    assert refused is not None and _status(report)["motion_service"] == "fail"
    assert _reason(report, "motion_service").startswith("built-in controller 'ai' active and "
                                                        "backend.release_motion_service is false")
    assert "cannot be overridden" in _reason(report, "motion_service")
    assert robot.service is not None
    robot.service.close()  # the service goes silent: the robot streams its state, nothing answers CheckMode
    report, refused, _ = preflight_only(path, partition)
    assert refused is not None and _status(report)["motion_service"] == "fail"
    assert _reason(report, "motion_service").startswith(
        "no motion service answered within 1.0 s, and backend.release_motion_service is true: the release would "
        "fail before control starts. If the robot is in debug mode already (L2+R2 on its remote), skip the release: "
        "--no-release-motion-service")
    assert "motion_service" in str(refused) and robot.endpoint.last_command is None
    report, refused, _ = preflight_only(path, partition, release_motion_service=False)
    assert refused is None and _status(report)["motion_service"] == "skip"
    assert robot.service.active_mode == "ai" and set(robot.service.calls) == {1001}  # asked, never released
    assert robot.endpoint.last_command is None
