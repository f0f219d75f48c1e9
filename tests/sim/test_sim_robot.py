"""`g1 sim-robot`: the MuJoCo G1 behind the robot's DDS protocol on loopback."""

from __future__ import annotations

import os
import subprocess
import sys
import time
import uuid
from pathlib import Path

import numpy as np
import pytest

from g1_control.errors import NetworkInterfaceError
from g1_control.hardware.dds_backend import UnitreeDDSBackend
from g1_control.hardware.unitree.motion_service import release_motion_service
from g1_control.robot import g1
from g1_control.rotations import tilt_rad
from g1_control.sim.emulator import RobotEmulator
from g1_control.sim.mock_robot import MockG1
from g1_control.types import MotorCommand

pytestmark = pytest.mark.timing

ROOT = Path(__file__).resolve().parents[2]


def _partition() -> str:
    return f"g1test-{os.getpid()}-{uuid.uuid4().hex[:8]}"


def _hold() -> MotorCommand:
    return MotorCommand(q_rad=g1.DEFAULT_Q_RAD.copy(), kp=g1.KP_DEFAULT.copy(), kd=g1.KD_DEFAULT.copy())


def test_mujoco_emulator_on_its_gantry_follows_host_commands_over_dds():
    partition = _partition()
    proc = subprocess.Popen(
        [sys.executable, "-m", "g1_control.cli.main", "sim-robot", "--gantry", "--partition", partition,
         "--seconds", "8"],
        cwd=ROOT, env={**os.environ, "PYTHONPATH": str(ROOT)}, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
        text=True)
    try:
        assert proc.stdout.readline().strip() == "ready"
        with UnitreeDDSBackend("lo", 1, partition=partition, connect_timeout_s=5.0,
                               motion_service_timeout_s=5.0, expected_mode_machine=5) as robot:
            state = robot.reset()
            assert robot.released_modes == ["ai"]
            arms_up = _hold()
            arms_up.q_rad[g1.JOINT_INDEX["left_shoulder_pitch_joint"]] = -1.0
            robot.write_command(arms_up)
            time.sleep(2.0)
            state = robot.read_state()
            stats = robot.stats()
        _, err = proc.communicate(timeout=20)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert tilt_rad(state.imu_quat_wxyz) < 0.2, "on its gantry the simulated G1 stays upright"
    shoulder = g1.JOINT_INDEX["left_shoulder_pitch_joint"]
    # From 0.2 rad towards -1.0: low policy gains (kp ~14 N m/rad) leave ~0.2 rad of sag under the arm's weight.
    assert -1.05 < state.q_rad[shoulder] < -0.6, "the commanded arm pose reached MuJoCo"
    legs = list(g1.LEG_JOINTS)
    assert np.max(np.abs(state.q_rad[legs] - g1.DEFAULT_Q_RAD[legs])) < 0.2, "the legs hold their pose"
    assert stats.bad_crc == 0 and stats.state_rate_hz > 100
    assert " 0 bad CRC, 0 wrong mode_machine" in err


def test_commands_are_ignored_until_the_builtin_controller_is_released():
    partition = _partition()
    emulator = RobotEmulator(MockG1(), "lo", 1, partition=partition).start()
    robot = UnitreeDDSBackend("lo", 1, partition=partition, release_motion_service=False, connect_timeout_s=4.0,
                              close_damping_s=0.05)
    try:
        robot.reset()
        robot.write_command(_hold())
        time.sleep(0.3)
        assert emulator.endpoint.counters.ignored_while_builtin_active > 10
        assert emulator.endpoint.counters.commands_applied == 0
        assert release_motion_service(robot.link._participant, partition) == ["ai"]
        time.sleep(0.3)
        assert emulator.endpoint.counters.commands_applied > 10
    finally:
        robot.close()
        emulator.close()


def test_emulator_refuses_non_loopback_interfaces():
    with pytest.raises(NetworkInterfaceError, match="loopback only .*got 'eth0'"):
        RobotEmulator(MockG1(), "eth0", 1)
