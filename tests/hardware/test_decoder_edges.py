"""The decoders' edges a mutation run found untested (issue 16): trailing bytes after a DDS sample,
decoding without a CRC check by default, float32 slots, default mode_pr, int16 temperatures that
saturate, an over-long remote field, 0/1 enable masks, the remote's zero header and idle bytes."""

from __future__ import annotations

import numpy as np
import pytest

from g1_control.errors import CrcMismatchError
from g1_control.hardware.unitree.conversions import (
    lowcmd_to_motor_command,
    lowstate_to_robot_state,
    motor_command_to_lowcmd,
    robot_state_to_lowstate,
)
from g1_control.hardware.unitree.messages import LowCmd, LowState
from g1_control.hardware.unitree.remote import encode_wireless_remote
from g1_control.robot import g1
from g1_control.types import MotorCommand, RobotState

N = g1.NUM_JOINTS
MODE_29DOF = 5


def _state(**kw) -> RobotState:
    return RobotState(t_s=0.0, q_rad=g1.DEFAULT_Q_RAD.copy(), mode_machine=MODE_29DOF, tick=7, **kw)


def test_bytes_after_a_dds_sample_are_ignored():
    state = _state()
    state.q_rad[3] = 0.75
    sample = robot_state_to_lowstate(state).to_dds()
    decoded = LowState.from_dds(sample + bytes(8), verify=True)
    np.testing.assert_array_equal(decoded.motor_q_rad, LowState.from_dds(sample).motor_q_rad)
    assert decoded.motor_q_rad[3] == np.float32(0.75)
    assert decoded.tick == 7


def test_decoding_checks_the_crc_only_when_asked():
    good = robot_state_to_lowstate(_state())
    for encode, decode in ((LowState.to_dds, LowState.from_dds), (LowState.to_c_bytes, LowState.from_c_bytes)):
        data = bytearray(encode(good))
        data[-1] ^= 0xFF  # the CRC's last byte
        bad = bytes(data)
        assert decode(bad).tick == 7, "the transport decodes and counts bad-CRC samples itself"
        with pytest.raises(CrcMismatchError):
            decode(bad, verify=True)


def test_a_lowcmd_holds_what_the_wire_carries():
    cmd = MotorCommand(q_rad=np.full(N, 0.1), dq_radps=np.full(N, 0.2), kp=np.full(N, 40.1), kd=np.full(N, 1.3),
                       tau_nm=np.full(N, 0.7))
    msg = motor_command_to_lowcmd(cmd, MODE_29DOF)
    back = lowcmd_to_motor_command(msg)
    for name in ("q_rad", "dq_radps", "kp", "kd", "tau_nm"):
        want = getattr(cmd, name).astype(np.float32).astype(np.float64)
        assert np.all(getattr(back, name) == want) and not np.all(want == getattr(cmd, name)), name
    assert np.all(LowCmd().motor_mode == 0) and LowCmd().motor_mode.tobytes() == bytes(35)


def test_mode_pr_defaults_to_pitch_roll():
    assert motor_command_to_lowcmd(MotorCommand(), MODE_29DOF).mode_pr == 0
    assert robot_state_to_lowstate(_state()).mode_pr == 0
    assert motor_command_to_lowcmd(MotorCommand(), MODE_29DOF, mode_pr=1).mode_pr == 1


def test_temperatures_beyond_int16_saturate_on_the_wire():
    temps = np.full(N, 40.0)
    temps[:4] = [40000.0, -40000.0, 32767.0, -32768.0]
    msg = LowState.from_dds(robot_state_to_lowstate(_state(motor_temperature_c=temps)).to_dds())
    np.testing.assert_array_equal(msg.motor_temperature_c[:4], [[32767] * 2, [-32768] * 2, [32767] * 2, [-32768] * 2])
    assert lowstate_to_robot_state(msg, 0.0).motor_temperature_c[0] == 32767.0


def test_an_over_long_remote_field_is_cut_to_40_bytes():
    long_remote = bytes(range(50))
    msg = robot_state_to_lowstate(_state(wireless_remote=long_remote))
    assert msg.wireless_remote == long_remote[:40]
    assert LowState.from_dds(msg.to_dds()).wireless_remote == long_remote[:40]


def test_an_enable_mask_of_numbers_is_read_as_a_mask():
    enable = np.ones(N, dtype=np.int64)
    enable[[0, 5]] = 0
    cmd = MotorCommand(kp=np.full(N, 50.0), enable=enable)
    msg = motor_command_to_lowcmd(cmd, MODE_29DOF)
    assert msg.motor_mode[0] == 0 and msg.motor_mode[5] == 0 and msg.motor_mode[1] == 1
    assert msg.motor_kp_nm_per_rad[0] == 0.0 and msg.motor_kp_nm_per_rad[1] == 50.0


def test_the_remote_header_and_idle_bytes_are_zero():
    data = encode_wireless_remote(["A", "L1"], lx=0.5, ly=-0.25)
    assert len(data) == 40 and data[:2] == b"\x00\x00" and data[24:] == bytes(16)
