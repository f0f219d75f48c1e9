"""The DDS transport over real Cyclone DDS 0.10.x on loopback (interface lo, domain 1).

Thresholds are loose on purpose: the host is shared and DDS rates sag under load (docs/robot_facts.md).
Each test uses its own DDS partition so that concurrent runs on this host never see each other.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time
import uuid
from pathlib import Path

import numpy as np
import pytest

from g1_control.errors import (
    MotionServiceError,
    NetworkInterfaceError,
    RobotNotConnectedError,
    VariantMismatchError,
)
from g1_control.hardware.dds_backend import UnitreeDDSBackend
from g1_control.hardware.links.dds import DdsLink, cyclone_config
from g1_control.hardware.unitree.motion_service import MotionServiceEmulator
from g1_control.robot import g1
from g1_control.sim.mock_robot import MockG1
from g1_control.sim.robot_endpoint import RobotEndpoint
from g1_control.types import MotorCommand

pytestmark = pytest.mark.timing

INTERFACE, DOMAIN = "lo", 1
ROOT = Path(__file__).resolve().parents[2]


def _partition() -> str:
    return f"g1test-{os.getpid()}-{uuid.uuid4().hex[:8]}"


def _env() -> dict:
    return {**os.environ, "PYTHONPATH": str(ROOT)}


def _hold_command() -> MotorCommand:
    return MotorCommand(q_rad=g1.DEFAULT_Q_RAD.copy(), kp=g1.KP_DEFAULT.copy(), kd=g1.KD_DEFAULT.copy())


def test_config_names_the_interface_and_never_multicasts_on_loopback():
    xml = cyclone_config("lo")
    assert '<NetworkInterface name="lo"' in xml
    assert "<AllowMulticast>false</AllowMulticast>" in xml and '<Peer address="127.0.0.1"/>' in xml


def test_two_processes_exchange_lowcmd_and_lowstate():
    partition = _partition()
    robot = subprocess.Popen(
        [sys.executable, "-m", "g1_control.sim.robot_endpoint", "--interface", INTERFACE,
         "--domain", str(DOMAIN), "--partition", partition, "--seconds", "6"],
        cwd=ROOT, env=_env(), stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        # Generous waits: on a loaded host the robot process needs seconds to import and start DDS
        # (its --seconds count from then on); this test is about the exchange, not start-up time.
        backend = UnitreeDDSBackend(INTERFACE, DOMAIN, partition=partition, connect_timeout_s=30.0,
                                    motion_service_timeout_s=30.0, expected_mode_machine=5)
        state = backend.reset()
        assert backend.released_modes == ["ai"]
        assert state.mode_machine == 5
        backend.write_command(_hold_command())
        time.sleep(1.0)
        stats = backend.stats()
        backend.close()
        out, _ = robot.communicate(timeout=15)
    finally:
        if robot.poll() is None:
            robot.kill()
    report = json.loads(out.strip().splitlines()[-1])
    print("host stats:", stats, "\nrobot:", {k: v for k, v in report.items() if k != "last_kp"})
    assert stats.bad_crc == 0 and stats.malformed == 0
    assert stats.state_rate_hz > 100, "nominal 500 Hz; far below means the stream is broken"
    assert stats.command_rate_hz > 100
    assert report["bad_crc"] == 0 and report["wrong_mode_machine"] == 0
    assert report["commands_applied"] > 150
    assert report["last_mode_machine"] == 5
    assert 1003 in report["motion_service_calls"] and report["motion_service_mode"] == ""
    # close() streams damping: the last command the robot applied has no stiffness.
    assert report["damping_commands"] > 0 and max(report["last_kp"]) == 0.0


def test_commands_and_states_interoperate_with_unitrees_own_types():
    partition = _partition()
    peer = subprocess.Popen([sys.executable, "-m", "tests.hardware.dds_official_peer", INTERFACE, str(DOMAIN), partition, "4"],
                            cwd=ROOT, env=_env(), stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        backend = UnitreeDDSBackend(INTERFACE, DOMAIN, partition=partition, release_motion_service=False,
                                    connect_timeout_s=30.0)
        state = backend.reset()
        assert state.mode_machine == 4 and state.wireless_remote == bytes(range(40))
        assert state.motor_temperature_c[0] == 33.0
        backend.write_command(_hold_command())
        time.sleep(1.0)
        stats = backend.stats()
        backend.close()
        out, err = peer.communicate(timeout=15)
    finally:
        if peer.poll() is None:
            peer.kill()
    assert peer.returncode == 0, err
    report = json.loads(out.strip().splitlines()[-1])
    assert stats.bad_crc == 0 and stats.states_received > 20
    assert report["received"] > 20 and report["crc_ok"] == report["checked"] == 20
    assert report["mode_machines"] == [4]


@pytest.fixture
def robot_in_process():
    partition = _partition()
    link = DdsLink("robot", INTERFACE, DOMAIN, partition=partition)
    endpoint = RobotEndpoint(link, MockG1(mode_machine=5)).start()
    yield partition, endpoint
    endpoint.stop()
    link.close()


def test_corrupted_state_crcs_are_counted_and_never_become_state(robot_in_process):
    partition, endpoint = robot_in_process
    backend = UnitreeDDSBackend(INTERFACE, DOMAIN, partition=partition, release_motion_service=False,
                                connect_timeout_s=4.0)
    try:
        backend.reset()
        endpoint.corrupt_state_crc = True
        time.sleep(0.2)  # let good samples already in flight drain
        last_good_tick = backend.read_state().tick
        time.sleep(0.3)
        stats = backend.stats()
        assert stats.bad_crc > 20
        assert backend.read_state().tick == last_good_tick
        endpoint.corrupt_state_crc = False
        time.sleep(0.3)
        assert backend.read_state().tick > last_good_tick
    finally:
        backend.close()


def test_nan_command_switches_the_stream_to_damping(robot_in_process):
    partition, endpoint = robot_in_process
    backend = UnitreeDDSBackend(INTERFACE, DOMAIN, partition=partition, release_motion_service=False,
                                connect_timeout_s=4.0, close_damping_s=0.0)
    try:
        backend.reset()
        backend.write_command(_hold_command())
        time.sleep(0.3)
        assert endpoint.last_command.motor_kp_nm_per_rad[3] > 0
        bad = _hold_command()
        bad.q_rad[3] = np.nan
        with pytest.raises(Exception, match="NaN or inf; the robot was switched to damping"):
            backend.write_command(bad)
        time.sleep(0.3)
        assert float(endpoint.last_command.motor_kp_nm_per_rad.max()) == 0.0
        assert float(endpoint.last_command.motor_kd_nms_per_rad[0]) > 0.0
    finally:
        backend.close()


def test_variant_mismatch_is_refused(robot_in_process):
    partition, _ = robot_in_process
    backend = UnitreeDDSBackend(INTERFACE, DOMAIN, partition=partition, release_motion_service=False,
                                connect_timeout_s=4.0, expected_mode_machine=4)
    try:
        with pytest.raises(VariantMismatchError, match="reports mode_machine 5 .*expects 4"):
            backend.reset()
    finally:
        backend.close()


def test_no_robot_and_wrong_interface_are_refused_with_advice():
    with pytest.raises(NetworkInterfaceError, match="'nonexistent0' does not exist; interfaces here: .*lo"):
        UnitreeDDSBackend("nonexistent0", DOMAIN)
    backend = UnitreeDDSBackend(INTERFACE, DOMAIN, partition=_partition(), release_motion_service=False,
                                connect_timeout_s=0.3)
    try:
        with pytest.raises(RobotNotConnectedError, match="no valid LowState from the robot within 0.3 s on DDS "
                                                         r"\(interface lo, domain 1"):
            backend.reset()
        with pytest.raises(RobotNotConnectedError):
            backend.write_command(_hold_command())
    finally:
        backend.close()


def test_silent_motion_service_is_reported():
    backend = UnitreeDDSBackend(INTERFACE, DOMAIN, partition=_partition(), motion_service_timeout_s=0.3)
    try:
        with pytest.raises(MotionServiceError, match="did not answer api 1001 .*--no-release-motion-service"):
            backend.reset()
    finally:
        backend.close()


def test_motion_service_release_in_process():
    partition = _partition()
    robot_link = DdsLink("robot", INTERFACE, DOMAIN, partition=partition)
    service = MotionServiceEmulator(robot_link._participant, partition, active_mode="ai_sport")
    endpoint = RobotEndpoint(robot_link, MockG1()).start()
    backend = UnitreeDDSBackend(INTERFACE, DOMAIN, partition=partition, connect_timeout_s=4.0,
                                motion_service_timeout_s=4.0)
    try:
        backend.reset()
        assert backend.released_modes == ["ai_sport"] and service.active_mode == ""
    finally:
        backend.close()
        endpoint.stop()
        service.close()
        robot_link.close()


def test_short_samples_are_counted_as_malformed_and_ignored(robot_in_process):
    partition, endpoint = robot_in_process
    backend = UnitreeDDSBackend(INTERFACE, DOMAIN, partition=partition, release_motion_service=False,
                                connect_timeout_s=4.0)
    try:
        backend.reset()
        endpoint.publish = False  # only the truncated samples below reach the host now
        time.sleep(0.05)
        tick = backend.read_state().tick
        from g1_control.hardware.unitree.messages import LowState

        short = LowState(mode_machine=5, tick=tick + 100).to_dds()[:600]
        for _ in range(10):
            endpoint.link.send(short)
            time.sleep(0.005)
        time.sleep(0.2)
        assert backend.stats().malformed >= 5
        assert backend.read_state().tick == tick
    finally:
        backend.close()
