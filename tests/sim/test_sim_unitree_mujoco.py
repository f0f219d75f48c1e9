"""The emulator playing Unitree's MuJoCo simulator (g1_control/sim/unitree_mujoco.py): its motor
law holds the PD torque computed when a command arrives; over DDS on loopback its LowState_ comes
at ~200 Hz with crc, tick and mode_machine 0, it takes any LowCmd_, and runs no motion service."""

from __future__ import annotations

import time

import numpy as np
import pytest

from g1_control.robot import g1
from g1_control.sim.mujoco_backend import MujocoBackend, MujocoConfig
from g1_control.sim.unitree_mujoco import PHYSICS_DT_S, HeldTorqueMujoco
from g1_control.types import MotorCommand

KNEE = g1.JOINT_INDEX["left_knee_joint"]


def _pd(q: np.ndarray) -> MotorCommand:
    target = q.copy()
    target[KNEE] += 0.3
    return MotorCommand(q_rad=target, kp=np.full(g1.NUM_JOINTS, 40.0), kd=np.full(g1.NUM_JOINTS, 1.0))


def test_the_pd_torque_is_computed_when_the_command_arrives_and_held():
    held = HeldTorqueMujoco()
    assert held.model.opt.timestep == pytest.approx(PHYSICS_DT_S) == pytest.approx(0.005)
    state = held.reset()
    command = _pd(state.q_rad)
    held.write_command(command)
    expected = command.kp[KNEE] * (command.q_rad[KNEE] - state.q_rad[KNEE]) - command.kd[KNEE] * state.dq_radps[KNEE]
    forces = []
    for _ in range(5):
        held.step(PHYSICS_DT_S)
        forces.append(held.data.actuator_force[KNEE])
    assert np.allclose(forces, expected, atol=1e-6)  # the same torque every step while the knee moves
    assert abs(held.read_state().q_rad[KNEE] - state.q_rad[KNEE]) > 1e-3

    # the robot's law (MujocoBackend) re-evaluates the PD every physics step instead
    robot = MujocoBackend(MujocoConfig(physics_dt_s=PHYSICS_DT_S))
    state = robot.reset()
    robot.write_command(_pd(state.q_rad))
    seen = []
    for _ in range(5):
        robot.step(PHYSICS_DT_S)
        seen.append(robot.data.actuator_force[KNEE])
    assert np.ptp(seen) > 0.5


@pytest.mark.timing
def test_the_emulator_in_unitree_mujoco_mode_speaks_as_that_simulator():
    from g1_control.hardware.links.dds import DdsLink
    from g1_control.hardware.unitree.conversions import motor_command_to_lowcmd
    from g1_control.hardware.unitree.motion_service import MotionServiceClient, MotionServiceError
    from g1_control.sim.emulator import RobotEmulator
    from g1_control.sim.mock_robot import MockG1
    from tests.deploy.deploy_test_helpers import new_partition

    partition = new_partition()
    robot = RobotEmulator(MockG1(), "lo", 1, partition=partition, mode="unitree_mujoco").start()
    host = DdsLink("host", "lo", 1, partition=partition)
    try:
        samples, t0 = [], time.monotonic()
        while time.monotonic() - t0 < 1.0:
            samples += host.receive(0.05)
        elapsed = time.monotonic() - t0
        assert 120 <= len(samples) / elapsed <= 230, len(samples) / elapsed  # 200 Hz (shared host: tolerant)
        for payload in samples[-10:]:
            msg = host.decode_state(payload, verify=False)
            assert (msg.crc, msg.tick, msg.mode_machine) == (0, 0, 0)
        # any LowCmd_: a foreign mode_machine and a zero CRC are taken
        cmd = motor_command_to_lowcmd(MotorCommand.damping(1.0), mode_machine=5)
        cmd.mode_machine = 0
        host.send(cmd.to_dds()[:-4] + bytes(4))
        deadline = time.monotonic() + 2.0
        while robot.endpoint.counters.commands_applied == 0 and time.monotonic() < deadline:
            time.sleep(0.02)
        assert robot.endpoint.counters.commands_applied >= 1
        assert robot.endpoint.counters.bad_crc == robot.endpoint.counters.wrong_mode_machine == 0
        assert robot.service is None and robot.report()["mode"] == "unitree_mujoco"
        # nobody answers the motion service
        client = MotionServiceClient(host._participant, partition, timeout_s=0.5)
        with pytest.raises(MotionServiceError, match="the robot's motion service did not answer"):
            client.check_mode()
    finally:
        host.close()
        robot.close()
