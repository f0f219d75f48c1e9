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


def test_a_limp_g1_hanging_in_the_elastic_band_stays_inside_its_joint_stops_and_comes_to_rest():
    """`g1 sim-robot --mode unitree_mujoco --lower-gantry-on-policy` before the host's first command:
    no motor torque, the robot hanging in the gantry. The preflight then finds every joint within
    its range (+ its tolerance), whenever it samples: on main the limp arms swung for good at up to
    10 rad/s and went 0.05 rad past their shoulder yaw stops (CI: right_shoulder_yaw_joint +2.640 rad)."""
    from g1_control.launch.schema import DeployConfig
    from g1_control.sim.emulator import Gantry

    held = HeldTorqueMujoco(MujocoConfig(lockstep=True, physics_dt_s=PHYSICS_DT_S))
    robot = Gantry(held, physics_dt_s=held.config.physics_dt_s, lower_on_policy=True)  # as g1 sim-robot builds it
    robot.reset()
    robot.write_command(MotorCommand.damping(g1.KD_DEFAULT))  # the emulator's start: a held torque of 0
    tolerance = DeployConfig().joint_limit_tolerance_rad
    worst, last_second_speed = np.zeros(g1.NUM_JOINTS), 0.0
    steps = round(30.0 / PHYSICS_DT_S)
    for step in range(steps):
        robot.step(PHYSICS_DT_S)
        state = robot.read_state()
        worst = np.maximum(worst, np.maximum(g1.Q_MIN_RAD - state.q_rad, state.q_rad - g1.Q_MAX_RAD))
        if step >= steps - round(1.0 / PHYSICS_DT_S):
            last_second_speed = max(last_second_speed, float(np.max(np.abs(state.dq_radps))))
    past = {g1.JOINT_NAMES[j]: round(float(worst[j]), 4) for j in np.nonzero(worst > tolerance)[0]}
    assert not past, f"joints went past their range by more than the preflight's {tolerance} rad: {past}"
    assert last_second_speed < 0.05, f"still swinging after 29 s: {last_second_speed:.2f} rad/s"
    resting = np.maximum(g1.Q_MIN_RAD - state.q_rad, state.q_rad - g1.Q_MAX_RAD)
    assert np.max(resting) < 0.001, f"{g1.JOINT_NAMES[int(np.argmax(resting))]} rests {np.max(resting):.4f} rad past its stop"
    assert state.base_pos_w_m is not None and state.base_pos_w_m[2] > 0.6  # still hanging


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
