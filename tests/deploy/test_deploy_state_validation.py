"""The robot's state is validated as a whole, at the preflight and every tick, over real DDS on
loopback (lo, domain 1, a partition per test) against emulated robots (MockG1 motors):

- a NaN joint (valid CRC) fails the preflight, so a `--yes` deploy never releases the motion service;
- a second publisher on rt/lowstate is refused at the preflight and trips a running deploy;
- a spoofed LowState_ with another mode_machine never makes the host send that mode_machine.

Every ending is damping on the wire, streamed with the mode_machine the preflight accepted."""

from __future__ import annotations

import threading
import time

import numpy as np
import pytest
from deploy_test_helpers import FAST, SecondPublisher, preflight_only, write_launch

from g1_control.deploy.preflight import PreflightRefused
from g1_control.deploy.session import DeployOptions, deploy
from g1_control.robot import g1

pytestmark = pytest.mark.timing


def _row(report, name: str) -> dict:
    return next(r for r in report.preflight if r["name"] == name)


def test_a_nan_joint_fails_the_preflight_and_nothing_is_released(tmp_path, partition, mock_robot):
    robot = mock_robot()
    knee = g1.JOINT_INDEX["left_knee_joint"]
    robot.physics.inner._q[knee] = np.nan
    robot.start()
    path = write_launch(tmp_path, FAST)
    report, refused, text = preflight_only(path, partition)
    print("\n" + text)
    assert refused is not None, text
    row = _row(report, "joint_limits")
    assert row["status"] == "fail", text
    assert "left_knee_joint" in row["reason"] and "nan" in row["reason"].lower()

    # With --yes the deploy is refused before anything is sent: the built-in controller keeps the robot.
    lines: list[str] = []
    try:
        deploy(path, DeployOptions(yes=True, partition=partition, duration_s=1.0), say=lines.append)
        raise AssertionError("a NaN joint was accepted:\n" + "\n".join(lines))
    except PreflightRefused:
        pass
    assert robot.service.active_mode == "ai", "the motion service was released for a robot reporting NaN"
    assert robot.endpoint.counters.commands_applied == 0


def test_a_second_lowstate_publisher_is_refused_at_the_preflight(tmp_path, partition, mock_robot):
    robot = mock_robot().start()
    spoof = SecondPublisher(partition, robot.physics.read_state).start(seconds=30.0)
    try:
        report, refused, text = preflight_only(write_launch(tmp_path, FAST), partition)
    finally:
        spoof.close()
    print("\n" + text)
    assert refused is not None, text
    row = next((r for r in report.preflight if "publisher" in r["reason"]), None)
    assert row is not None and row["status"] == "fail", text
    assert "2 publishers on rt/lowstate" in row["reason"], row


def _deploy_with_spoof(tmp_path, partition, mock_robot, mode_machine: int, spoof_s: float):
    """An emulated robot and a --yes deploy to it (3 s of control) during which a second publisher sends
    `spoof_s` of LowState_ with `mode_machine`, starting 0.5 s into control; the deploy must end without
    an exception. Returns (robot, report, spoof)."""
    robot = mock_robot().start()
    spoof = SecondPublisher(partition, robot.physics.read_state, mode_machine=mode_machine)
    control = threading.Event()
    lines: list[str] = []

    def say(line: str) -> None:
        lines.append(line)
        if "hold -> control" in line and not control.is_set():
            control.set()
            spoof.start(seconds=spoof_s, delay_s=0.5)

    launch = write_launch(tmp_path, {"deploy": {"state_window_s": 0.3, "input_check_s": 0.1}})
    report, error = None, None
    try:
        report = deploy(launch, DeployOptions(yes=True, partition=partition, duration_s=3.0), say=say)
    except Exception as exc:
        error = exc
    finally:
        spoof.close()
    time.sleep(0.2)
    text = "\n".join(lines)
    print("\n" + text)
    assert error is None, f"{error!r}\n{text}"
    return robot, report, spoof


def test_a_spoofed_mode_machine_mid_run_trips_and_never_reaches_the_wire(tmp_path, partition, mock_robot):
    robot, report, spoof = _deploy_with_spoof(tmp_path, partition, mock_robot, mode_machine=4, spoof_s=1.0)
    assert spoof.sent > 100, "the second publisher ran"
    wire = robot.report()
    assert wire["wrong_mode_machine"] == 0, f"{wire['wrong_mode_machine']} LowCmd_ frames carried the spoofed " \
        "mode_machine"
    assert report.fault, f"the deploy ended as planned ({report.end_reason}) although the state was spoofed"
    assert "mode_machine" in report.end_reason or "publisher" in report.end_reason, report.end_reason
    assert report.sequence[-1] == "damping"
    assert wire["last_command_is_damping"] is True


def test_a_second_publisher_appearing_mid_run_trips(tmp_path, partition, mock_robot):
    robot, report, _spoof = _deploy_with_spoof(tmp_path, partition, mock_robot, mode_machine=5, spoof_s=1.0)
    assert report.fault, f"the deploy ended as planned ({report.end_reason}) with a second publisher"
    assert "publisher" in report.end_reason or "tick" in report.end_reason, report.end_reason
    assert robot.report()["last_command_is_damping"] is True


def test_the_robot_changing_its_mode_machine_mid_run_trips_naming_it(tmp_path, partition, mock_robot):
    """No second publisher: the robot itself reports mode_machine 4 for 1 s during control. The deploy
    trips naming the field and keeps streaming the accepted mode_machine (5), which a robot of another
    variant drops; once it reports 5 again, it takes the damping."""
    robot = mock_robot().start()
    mock = robot.physics.inner
    control = threading.Event()
    lines: list[str] = []

    def flip() -> None:
        time.sleep(0.5)
        mock.mode_machine = 4
        time.sleep(1.0)
        mock.mode_machine = 5

    def say(line: str) -> None:
        lines.append(line)
        if "hold -> control" in line and not control.is_set():
            control.set()
            threading.Thread(target=flip, daemon=True).start()

    launch = write_launch(tmp_path, {"deploy": {"state_window_s": 0.3, "input_check_s": 0.1,
                                                "exit_damping_s": 2.0}})
    report = deploy(launch, DeployOptions(yes=True, partition=partition, duration_s=3.0, out_root=tmp_path),
                    say=say)
    print("\n" + "\n".join(lines))
    time.sleep(0.2)
    wire = robot.report()
    assert report.fault and report.end_reason == "RobotState.mode_machine changed from 5 to 4 (another DoF " \
        "variant, or a second publisher)", report.end_reason
    assert wire["wrong_mode_machine"] > 0, "the host kept the accepted mode_machine while the robot reported 4"
    assert wire["last_command_is_damping"] is True and wire["damping_commands"] > 0
