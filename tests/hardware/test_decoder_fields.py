"""Every field of the decoders carries its own value (mutation testing found dq, tau, gyro and acc could
be dropped, and the C-image gate and remote axes renamed, without a test noticing), and their error
messages say exactly what is wrong."""

from __future__ import annotations

import numpy as np
import pytest

from g1_control.errors import CrcMismatchError, MalformedMessageError, RemoteDecodeError
from g1_control.hardware.unitree.conversions import (
    MOTOR_DISABLED,
    MOTOR_ENABLED,
    lowcmd_to_motor_command,
    lowstate_to_robot_state,
    motor_command_to_lowcmd,
    robot_state_to_lowstate,
)
from g1_control.hardware.unitree.messages import LowCmd, LowState, compute_crc
from g1_control.hardware.unitree.remote import (
    REMOTE_BUTTON_BITS,
    RemoteReading,
    decode_wireless_remote,
    encode_wireless_remote,
)
from g1_control.robot import g1
from g1_control.types import MotorCommand, RobotState

N = g1.NUM_JOINTS


def _distinct_state() -> LowState:
    msg = LowState(mode_pr=1, mode_machine=5, tick=0xFFFF_FFF0)
    k = np.arange(35, dtype=np.float32)
    msg.motor_q_rad[:] = 0.01 * k
    msg.motor_dq_radps[:] = 0.1 * k + 0.5
    msg.motor_tau_est_nm[:] = -0.2 * k
    msg.motor_temperature_c[:] = np.stack([k.astype(np.int16) + 20, k.astype(np.int16) + 25], axis=1)
    msg.imu_quat_wxyz[:] = [0.9, 0.1, -0.2, 0.3]
    msg.imu_gyro_radps[:] = [0.4, -0.5, 0.6]
    msg.imu_acc_mps2[:] = [0.1, 0.2, 9.7]
    msg.wireless_remote = bytes(range(40))
    return msg


def test_lowstate_to_robot_state_carries_every_field():
    msg = LowState.from_dds(_distinct_state().to_dds(), verify=True)
    s = lowstate_to_robot_state(msg, 12.5)
    k = np.arange(N, dtype=np.float32)
    assert s.t_s == 12.5 and s.mode_machine == 5 and s.tick == 0xFFFF_FFF0
    for name, expected in (("q_rad", 0.01 * k), ("dq_radps", 0.1 * k + 0.5), ("tau_nm", -0.2 * k),
                           ("imu_quat_wxyz", np.float32([0.9, 0.1, -0.2, 0.3])),
                           ("imu_gyro_radps", np.float32([0.4, -0.5, 0.6])),
                           ("imu_acc_mps2", np.float32([0.1, 0.2, 9.7])),
                           ("motor_temperature_c", k + 25)):
        value = getattr(s, name)
        assert value.dtype == np.float64 and value.shape == np.shape(expected), name
        np.testing.assert_array_equal(value, np.asarray(expected, dtype=np.float64), err_msg=name)
    assert s.wireless_remote == bytes(range(40))


def test_robot_state_to_lowstate_fills_every_field_and_wraps_the_tick():
    state = RobotState(q_rad=np.linspace(-1, 1, N), dq_radps=np.linspace(2, 3, N), tau_nm=np.linspace(-5, 5, N),
                       imu_quat_wxyz=np.array([0.5, 0.5, 0.5, 0.5]), imu_gyro_radps=np.array([1.0, 2.0, 3.0]),
                       imu_acc_mps2=np.array([4.0, 5.0, 6.0]), motor_temperature_c=np.full(N, 41.6),
                       mode_machine=4, tick=2**32 + 7, wireless_remote=bytes(range(10)))
    msg = robot_state_to_lowstate(state, mode_pr=1)
    assert msg.mode_pr == 1 and msg.mode_machine == 4 and msg.tick == 7
    np.testing.assert_allclose(msg.motor_q_rad[:N], state.q_rad, atol=1e-6)
    np.testing.assert_allclose(msg.motor_dq_radps[:N], state.dq_radps, atol=1e-6)
    np.testing.assert_allclose(msg.motor_tau_est_nm[:N], state.tau_nm, atol=1e-6)
    np.testing.assert_allclose(msg.imu_quat_wxyz, 0.5)
    np.testing.assert_allclose(msg.imu_gyro_radps, [1, 2, 3])
    np.testing.assert_allclose(msg.imu_acc_mps2, [4, 5, 6])
    assert np.all(msg.motor_temperature_c[:N] == 42)
    active = g1.variant_for_mode_machine(4).active_mask
    np.testing.assert_array_equal(msg.motor_mode[:N], np.where(active, MOTOR_ENABLED, MOTOR_DISABLED))
    assert msg.wireless_remote == bytes(range(10)) + bytes(30)


def test_lowcmd_to_motor_command_gates_disabled_motors():
    msg = LowCmd(mode_machine=5)
    msg.motor_mode[:N] = MOTOR_ENABLED
    msg.motor_mode[3] = MOTOR_DISABLED
    msg.motor_q_rad[:N] = 0.3
    msg.motor_dq_radps[:N] = 0.2
    msg.motor_kp_nm_per_rad[:N] = 40.0
    msg.motor_kd_nms_per_rad[:N] = 2.0
    msg.motor_tau_nm[:N] = 1.5
    cmd = lowcmd_to_motor_command(msg)
    assert cmd.enable.dtype == bool and cmd.enable.sum() == N - 1 and not cmd.enable[3]
    for name, value in (("kp", 40.0), ("kd", 2.0), ("tau_nm", 1.5)):
        arr = getattr(cmd, name)
        assert arr.dtype == np.float64 and arr[3] == 0.0 and np.all(np.delete(arr, 3) == value), name
    assert np.all(np.isfinite(cmd.kp)), "a disabled motor is gated to zero, never divided"
    np.testing.assert_allclose(cmd.q_rad, 0.3, rtol=1e-6)
    np.testing.assert_allclose(cmd.dq_radps, 0.2, rtol=1e-6)


def test_motor_command_to_lowcmd_reuses_the_given_message():
    out = LowCmd()
    command = MotorCommand(q_rad=g1.DEFAULT_Q_RAD.copy(), kp=g1.KP_DEFAULT.copy(), kd=g1.KD_DEFAULT.copy())
    msg = motor_command_to_lowcmd(command, 5, 0, out=out)
    assert msg is out and out.mode_machine == 5 and np.all(out.motor_mode[:N] == MOTOR_ENABLED)
    np.testing.assert_allclose(out.motor_kp_nm_per_rad[:N], g1.KP_DEFAULT, rtol=1e-6)
    assert np.all(out.motor_mode[N:] == MOTOR_DISABLED) and np.all(out.motor_kp_nm_per_rad[N:] == 0)


def test_decoder_messages_say_what_is_wrong():
    good = LowState(mode_machine=5).to_dds()
    with pytest.raises(MalformedMessageError) as info:
        LowState.from_dds(good[:100])
    assert str(info.value) == (f"LowState_ sample is 100 bytes; a complete one is {len(good)} (truncated sample, "
                               "or another message type on this topic)")
    with pytest.raises(MalformedMessageError) as info:
        LowState.from_dds(b"\x01\x00\x00\x00" + good[4:])
    assert str(info.value) == ("LowState_ sample starts with encapsulation 01000000; expected little-endian CDR "
                               "(0001 or 0007): the sender is not a G1 or uses a big-endian encoding")
    xcdr2 = b"\x00\x07\x00\x00" + good[4:]
    assert LowState.from_dds(xcdr2, verify=True).mode_machine == 5, "XCDR2 little endian: the same payload"
    with pytest.raises(MalformedMessageError, match=r"^LowCmd_ image is 3 bytes; expected exactly 1004$"):
        LowCmd.from_c_bytes(b"abc")
    bad = bytearray(LowCmd(mode_machine=5).to_c_bytes())
    bad[10] ^= 0xFF
    with pytest.raises(CrcMismatchError) as info:
        LowCmd.from_c_bytes(bytes(bad), verify=True)
    assert str(info.value).startswith("LowCmd CRC is 0x") and str(info.value).endswith(
        "the sample was corrupted or built by a sender that does not compute the G1 CRC")


def test_message_scalars_decode_as_python_ints():
    msg = LowState.from_c_bytes(LowState(mode_pr=1, mode_machine=6, tick=77, imu_temperature_c=-3).to_c_bytes(),
                                verify=True)
    for name, value in (("mode_pr", 1), ("mode_machine", 6), ("tick", 77), ("imu_temperature_c", -3)):
        assert type(getattr(msg, name)) is int and getattr(msg, name) == value, name
    assert msg.crc == compute_crc(msg)


def test_remote_axes_and_buttons_round_trip_by_name():
    data = encode_wireless_remote({"L1", "R1", "A"}, lx=0.1, rx=-0.2, ry=0.3, l2=0.4, ly=-0.5)
    reading = decode_wireless_remote(data)
    assert reading.buttons == {"L1", "R1", "A"}
    assert reading.axes() == pytest.approx({"lx": 0.1, "ly": -0.5, "rx": -0.2, "ry": 0.3, "L2": 0.4})
    assert set(reading.axes()) == {"lx", "ly", "rx", "ry", "L2"}
    assert decode_wireless_remote(encode_wireless_remote()) == RemoteReading(frozenset(), 0.0, 0.0, 0.0, 0.0, 0.0)
    for bit, name in enumerate(REMOTE_BUTTON_BITS):
        assert int.from_bytes(encode_wireless_remote({name})[2:4], "little") == 1 << bit
    with pytest.raises(RemoteDecodeError) as info:
        encode_wireless_remote({"Z"})
    assert str(info.value) == f"unknown remote buttons ['Z']; known: {', '.join(REMOTE_BUTTON_BITS)}"
    with pytest.raises(RemoteDecodeError, match=r"^wireless_remote has 39 bytes; expected 40$"):
        decode_wireless_remote(bytes(39))
