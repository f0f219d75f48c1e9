from __future__ import annotations

import numpy as np
import pytest

from g1_control.errors import VariantMismatchError
from g1_control.hardware.unitree import conversions as conv
from g1_control.hardware.unitree.messages import LowCmd, LowState, verify_crc
from g1_control.robot import g1
from g1_control.types import MotorCommand, RobotState


def _command(seed=0) -> MotorCommand:
    rng = np.random.default_rng(seed)
    return MotorCommand(q_rad=rng.uniform(-1, 1, 29), dq_radps=rng.uniform(-1, 1, 29),
                        kp=rng.uniform(10, 100, 29), kd=rng.uniform(1, 5, 29), tau_nm=rng.uniform(-3, 3, 29))


def test_29dof_command_round_trips_through_the_wire_and_echoes_mode_machine():
    cmd = _command()
    msg = conv.motor_command_to_lowcmd(cmd, mode_machine=5, mode_pr=0)
    back = LowCmd.from_dds(msg.to_dds())
    verify_crc(back)
    assert back.mode_machine == 5 and back.mode_pr == 0
    assert list(back.motor_mode[:29]) == [1] * 29 and list(back.motor_mode[29:]) == [0] * 6
    robot_view = conv.lowcmd_to_motor_command(back)
    np.testing.assert_allclose(robot_view.q_rad, cmd.q_rad, atol=1e-6)
    np.testing.assert_allclose(robot_view.kp, cmd.kp, rtol=1e-6)


@pytest.mark.parametrize("mode_machine, dropped", [
    (4, ["waist_roll_joint", "waist_pitch_joint", "left_wrist_pitch_joint", "left_wrist_yaw_joint",
         "right_wrist_pitch_joint", "right_wrist_yaw_joint"]),
    (6, ["waist_roll_joint", "waist_pitch_joint"]),
])
def test_joints_a_variant_lacks_go_out_disabled_with_zero_fields(mode_machine, dropped):
    msg = conv.motor_command_to_lowcmd(_command(), mode_machine=mode_machine)
    idx = [g1.JOINT_INDEX[n] for n in dropped]
    assert np.all(msg.motor_mode[idx] == 0)
    assert np.all(msg.motor_kp_nm_per_rad[idx] == 0) and np.all(msg.motor_q_rad[idx] == 0)
    others = [i for i in range(29) if i not in idx]
    assert np.all(msg.motor_mode[others] == 1)


def test_per_joint_disable_is_honoured():
    cmd = _command()
    cmd.enable[3] = False
    msg = conv.motor_command_to_lowcmd(cmd, mode_machine=5)
    assert msg.motor_mode[3] == 0 and msg.motor_kd_nms_per_rad[3] == 0
    assert conv.lowcmd_to_motor_command(msg).kd[3] == 0


def test_unknown_mode_machine_and_mode_pr_are_refused():
    with pytest.raises(VariantMismatchError, match="mode_machine 9"):
        conv.motor_command_to_lowcmd(_command(), mode_machine=9)
    with pytest.raises(ValueError, match="mode_pr must be 0"):
        conv.motor_command_to_lowcmd(_command(), mode_machine=5, mode_pr=2)


def test_lowstate_to_robot_state_passes_remote_bytes_and_takes_hotter_sensor():
    msg = LowState(mode_machine=5, tick=42)
    msg.motor_q_rad[:29] = np.linspace(-1, 1, 29)
    msg.imu_quat_wxyz[:] = [0.0, 1.0, 0.0, 0.0]
    msg.motor_temperature_c[7] = [40, 61]
    msg.wireless_remote = bytes(range(40))
    state = conv.lowstate_to_robot_state(LowState.from_dds(msg.to_dds()), t_s=12.5)
    assert state.t_s == 12.5 and state.tick == 42 and state.mode_machine == 5
    assert state.wireless_remote == bytes(range(40))
    assert state.motor_temperature_c[7] == 61.0
    np.testing.assert_allclose(state.q_rad, np.linspace(-1, 1, 29), atol=1e-6)
    np.testing.assert_array_equal(state.imu_quat_wxyz, [0, 1, 0, 0])


def test_robot_state_to_lowstate_round_trip():
    state = RobotState(q_rad=g1.DEFAULT_Q_RAD.copy(), mode_machine=4, tick=7,
                       wireless_remote=b"\x01\x02", motor_temperature_c=np.full(29, 33.4))
    back = conv.lowstate_to_robot_state(LowState.from_dds(conv.robot_state_to_lowstate(state).to_dds()), 0.0)
    np.testing.assert_allclose(back.q_rad, g1.DEFAULT_Q_RAD, atol=1e-6)
    assert back.wireless_remote == b"\x01\x02" + bytes(38)
    assert back.motor_temperature_c[0] == 33.0 and back.mode_machine == 4
