"""The Dex3-1 hand messages (HandCmd_/HandState_): known-answer serialisation, the motor mode byte,
round trips, malformed samples refused, and agreement with Unitree's own definitions."""

from __future__ import annotations

import struct

import numpy as np
import pytest

from g1_control.errors import MalformedMessageError
from g1_control.hardware.unitree.hand_idl import HandCmd_, HandState_
from g1_control.hardware.unitree.hand_messages import (
    finger_command_to_handcmd,
    finger_state_to_handstate,
    handcmd_to_finger_command,
    handstate_to_finger_state,
)
from g1_control.robot import dex3
from g1_control.types import FingerCommand, FingerState

XCDR1_LE = bytes.fromhex("00010000")


def _command() -> FingerCommand:
    enable = np.ones(7, dtype=bool)
    enable[4] = False
    return FingerCommand(q_rad=np.arange(7) * 0.25 - 0.5, dq_radps=np.full(7, 0.125), kp=np.full(7, 1.5),
                         kd=np.full(7, 0.1), tau_nm=(np.arange(7) + 1) * -0.0625, enable=enable)


def _expected_handcmd_bytes(c: FingerCommand) -> bytes:
    """HandCmd_ under XCDR1 written out field by field: sequence length, then per MotorCmd_ mode u8
    (3 bytes padding to the float), q dq tau kp kd f32, reserve u32; then reserve u32[4]."""
    out = XCDR1_LE + struct.pack("<I", 7)
    for i in range(7):
        mode = i | ((1 if c.enable[i] else 0) << 4)
        out += struct.pack("<B3x5fI", mode, c.q_rad[i], c.dq_radps[i], c.tau_nm[i], c.kp[i], c.kd[i], 0)
    return out + struct.pack("<4I", 0, 0, 0, 0)


def test_handcmd_serialises_to_the_known_bytes():
    data = finger_command_to_handcmd(_command()).serialize()
    assert data == _expected_handcmd_bytes(_command())
    assert len(data) == 4 + 4 + 7 * 28 + 16
    # the first motor spelled out: mode 0x10 (id 0, enabled), q -0.5, dq 0.125, tau -0.0625, kp 1.5, kd 0.1
    words = ["10000000", "000000bf", "0000003e", "000080bd", "0000c03f", "cdcccc3d", "00000000"]
    assert data[8:36].hex() == "".join(words)


def test_handstate_serialises_to_the_known_bytes():
    state = FingerState(q_rad=np.linspace(-0.3, 0.3, 7), dq_radps=np.full(7, -0.5), tau_nm=np.full(7, 0.25),
                        temperature_c=np.full(7, 41.0), motor_enabled=np.ones(7, dtype=bool), power_v=24.5,
                        power_a=0.75, error=(3, 0))
    pads = np.arange(24, dtype=float).reshape(2, 12)
    data = finger_state_to_handstate(state, pressure=pads).serialize()
    # XCDR1 by hand: MotorState_ = mode u8 +3, q dq ddq tau_est f32, temperature i16[2], vol f32,
    # sensor u32[2], motorstate u32, reserve u32[4] (56 bytes); PressSensorState_ = 24 f32, lost,
    # reserve u32 (104); IMUState_ = 13 f32 + i16 (54, then 2 bytes padding before power_v).
    want = XCDR1_LE + struct.pack("<I", 7)
    for i in range(7):
        want += struct.pack("<B3x4f2hf2II4I", 0x10 | i, state.q_rad[i], -0.5, 0.0, 0.25, 41, 41, 24.5, 0, 0, 0,
                            0, 0, 0, 0)
    want += struct.pack("<I", 2)
    for row in pads:
        want += struct.pack("<12f12fII", *row, *([0.0] * 12), 0, 0)
    want += struct.pack("<13fh2x", 1.0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0)
    want += struct.pack("<4f2I2I", 24.5, 0.75, 24.5, 24.5, 3, 0, 0, 0)
    assert data == want


def test_command_and_state_round_trip_through_the_wire():
    c = _command()
    back = handcmd_to_finger_command(HandCmd_.deserialize(finger_command_to_handcmd(c).serialize()))
    np.testing.assert_allclose(back.q_rad, c.q_rad.astype(np.float32))
    np.testing.assert_allclose(back.kd, c.kd.astype(np.float32))
    np.testing.assert_array_equal(back.enable, c.enable)
    s = FingerState(q_rad=np.linspace(0, 0.6, 7), tau_nm=np.full(7, -0.2), temperature_c=np.full(7, 38.0),
                    motor_enabled=np.ones(7, dtype=bool), power_v=24.0, error=(0, 5))
    got = handstate_to_finger_state(HandState_.deserialize(finger_state_to_handstate(s).serialize()), t_s=12.5)
    np.testing.assert_allclose(got.q_rad, s.q_rad.astype(np.float32))
    np.testing.assert_allclose(got.tau_nm, s.tau_nm.astype(np.float32))
    assert got.error == (0, 5) and got.t_s == 12.5 and got.motor_enabled.all()


def test_motor_mode_byte_packs_id_status_and_timeout():
    assert dex3.motor_mode(0) == 0x10
    assert dex3.motor_mode(6) == 0x16
    assert dex3.motor_mode(3, enabled=False) == 0x03
    assert dex3.motor_mode(2, timeout=True) == 0x92
    assert dex3.mode_enabled(0x15) and not dex3.mode_enabled(0x05)
    with pytest.raises(ValueError, match="motor index must be 0..6; got 7"):
        dex3.motor_mode(7)


def test_a_state_of_another_hand_model_is_refused_by_name():
    s = finger_state_to_handstate(FingerState())
    s.motor_state = s.motor_state[:6]
    with pytest.raises(MalformedMessageError, match="HandState_.motor_state holds 6 entries; a Dex3-1 hand has 7"):
        handstate_to_finger_state(s, 0.0)
    c = finger_command_to_handcmd(FingerCommand())
    c.motor_cmd = c.motor_cmd * 2
    with pytest.raises(MalformedMessageError, match="HandCmd_.motor_cmd holds 14 entries"):
        handcmd_to_finger_command(c)


def test_unitree_definitions_read_and_write_the_same_bytes():
    """Unitree's SDK types (unitree_sdk2 1.0.1, tests/hardware/unitree_reference.py) decode our samples
    and re-encode them byte for byte; our types decode theirs."""
    from tests.hardware.unitree_reference import hg

    ours_cmd = finger_command_to_handcmd(_command()).serialize()
    theirs = hg.HandCmd_.deserialize(ours_cmd)
    assert theirs.serialize() == ours_cmd
    assert theirs.__class__.__dataclass_fields__.keys() == HandCmd_.__dataclass_fields__.keys()
    ours_state = finger_state_to_handstate(FingerState(q_rad=np.full(7, 0.1), power_v=23.0),
                                           pressure=np.ones((3, 12))).serialize()
    theirs_state = hg.HandState_.deserialize(ours_state)
    assert theirs_state.serialize() == ours_state
    assert list(theirs_state.__dataclass_fields__) == list(HandState_.__dataclass_fields__)
    assert HandCmd_.__idl_typename__ == theirs.__idl_typename__ == "unitree_hg.msg.dds_.HandCmd_"
