"""Fuzzing the decoders of everything the robot sends (hypothesis): random bytes, truncated samples,
flipped bits and random contents never crash a decoder (only its own MalformedMessageError,
CrcMismatchError or RemoteDecodeError) and never pass as valid; a CRC-valid LowState_ carrying any
values never becomes a state the safety layer acts on unless every value is finite and in range.

Each test runs EXAMPLES examples (300; G1_FUZZ_EXAMPLES overrides)."""

from __future__ import annotations

import math
import os
import struct

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from g1_control.errors import CrcMismatchError, MalformedMessageError, RemoteDecodeError
from g1_control.hardware.links.framing import KIND_LOWSTATE, Deframer, encode_frame
from g1_control.hardware.unitree.conversions import lowstate_to_robot_state
from g1_control.hardware.unitree.messages import LowCmd, LowState
from g1_control.hardware.unitree.remote import REMOTE_SIZE, decode_wireless_remote, encode_wireless_remote
from g1_control.robot import g1
from g1_control.safety import SafetyFilter

DECODE_ERRORS = (MalformedMessageError, CrcMismatchError)
EXAMPLES = int(os.environ.get("G1_FUZZ_EXAMPLES", "300"))
"""Examples per fuzz test (scripts/mutation.py lowers it: each mutant runs these tests again)."""
FUZZ = settings(max_examples=EXAMPLES, deadline=None, suppress_health_check=[HealthCheck.too_slow])
MESSAGES = {"LowState_": LowState, "LowCmd_": LowCmd}


def _valid(cls) -> object:
    if cls is LowState:
        msg = LowState(mode_machine=5, tick=123)
        msg.motor_q_rad[: g1.NUM_JOINTS] = g1.DEFAULT_Q_RAD
        return msg
    msg = LowCmd(mode_machine=5)
    msg.motor_kp_nm_per_rad[: g1.NUM_JOINTS] = 40.0
    return msg


@pytest.mark.parametrize("name", MESSAGES)
@pytest.mark.parametrize("form", ["dds", "c"])
@FUZZ
@given(data=st.binary(max_size=2400))
def test_random_bytes_never_decode(name, form, data):
    cls = MESSAGES[name]
    decode = cls.from_dds if form == "dds" else cls.from_c_bytes
    with pytest.raises(DECODE_ERRORS):
        decode(data, verify=True)


@pytest.mark.parametrize("name", MESSAGES)
@pytest.mark.parametrize("form", ["dds", "c"])
@FUZZ
@given(cut=st.integers(min_value=0, max_value=4096))
def test_truncated_samples_are_malformed(name, form, cut):
    cls = MESSAGES[name]
    msg = _valid(cls)
    whole = msg.to_dds() if form == "dds" else msg.to_c_bytes()
    cut = cut % len(whole)
    decode = cls.from_dds if form == "dds" else cls.from_c_bytes
    with pytest.raises(MalformedMessageError):
        decode(whole[:cut], verify=True)


@pytest.mark.parametrize("name", MESSAGES)
@pytest.mark.parametrize("form", ["dds", "c"])
@FUZZ
@given(bit=st.integers(min_value=0), extra=st.binary(max_size=8))
def test_a_flipped_bit_is_caught(name, form, bit, extra):
    """One bit flipped anywhere in a valid sample: the CRC (or the header check) refuses it."""
    cls = MESSAGES[name]
    msg = _valid(cls)
    whole = bytearray(msg.to_dds() if form == "dds" else msg.to_c_bytes())
    bit %= len(whole) * 8
    whole[bit // 8] ^= 1 << (bit % 8)
    decode = cls.from_dds if form == "dds" else cls.from_c_bytes
    if form == "dds" and bit // 8 >= 4:
        # DDS padding bytes (alignment) are outside the C image the CRC covers: a flip there changes nothing.
        try:
            out = decode(bytes(whole), verify=True)
        except DECODE_ERRORS:
            return
        assert out.to_c_bytes() == msg.to_c_bytes(), "a flipped bit changed the contents yet passed the CRC"
        return
    with pytest.raises(DECODE_ERRORS):
        decode(bytes(whole), verify=True)


@FUZZ
@given(chunks=st.lists(st.binary(max_size=600), max_size=12))
def test_deframer_never_crashes_and_only_yields_checksummed_frames(chunks):
    deframer = Deframer()
    frames = [f for c in chunks for f in deframer.feed(c)]
    for frame in frames:  # a frame out of random bytes needs a CRC-32 match: astronomically rare
        assert frame.kind in (1, 2)
    assert deframer.counters.frames == len(frames)


@FUZZ
@given(noise=st.binary(max_size=300), cut=st.integers(min_value=0, max_value=3000))
def test_deframer_recovers_a_frame_after_noise_and_drops_a_cut_one(noise, cut):
    frame = encode_frame(KIND_LOWSTATE, 7, LowState(mode_machine=5).to_c_bytes())
    deframer = Deframer()
    got = deframer.feed(noise + frame[: cut % len(frame)])
    got += deframer.feed(frame)
    assert any(f.payload == frame[7:-4] for f in got)


@FUZZ
@given(data=st.binary(max_size=80))
def test_remote_bytes_of_the_wrong_size_are_refused(data):
    if len(data) == REMOTE_SIZE:
        _check_remote_layout(data)
        return
    with pytest.raises(RemoteDecodeError):
        decode_wireless_remote(data)


@FUZZ
@given(data=st.binary(min_size=REMOTE_SIZE, max_size=REMOTE_SIZE))
def test_any_40_remote_bytes_decode_as_the_documented_layout(data):
    _check_remote_layout(data)


def _check_remote_layout(data: bytes) -> None:
    """The documented layout read byte by byte (docs/robot_facts.md): bytes 2-3 a little-endian u16 whose
    bit i is R1, L1, start, select, R2, L2, F1, F2, A, B, X, Y, up, right, down, left; little-endian f32
    lx [4:8], rx [8:12], ry [12:16], L2 [16:20], ly [20:24] (NaN kept as NaN)."""
    names = ("R1", "L1", "start", "select", "R2", "L2", "F1", "F2", "A", "B", "X", "Y", "up", "right", "down", "left")
    bits = data[2] | data[3] << 8
    reading = decode_wireless_remote(data)
    assert reading.buttons == {name for i, name in enumerate(names) if bits >> i & 1}
    sticks = np.frombuffer(data, dtype="<f4", count=5, offset=4).astype(float)
    np.testing.assert_array_equal([reading.lx, reading.rx, reading.ry, reading.l2, reading.ly], sticks)


@FUZZ
@given(data=st.binary(min_size=REMOTE_SIZE, max_size=REMOTE_SIZE))
def test_any_remote_sample_maps_to_a_valid_command_or_none(data):
    """The operator side of the remote: random bytes (NaN sticks included) never make an invalid Command."""
    from g1_control.teleop.unitree_remote import UnitreeRemote

    remote = UnitreeRemote(state_source=lambda: _state_with_remote(data))
    command = remote.poll(0.0)
    for value in (command.vx_mps, command.vy_mps, command.wz_radps):
        assert math.isfinite(value)
    command.validate()


def _state_with_remote(data: bytes):
    from g1_control.types import RobotState

    return RobotState(wireless_remote=bytes(data))


FLOATS = st.floats(allow_nan=True, allow_infinity=True, width=32)


@FUZZ
@given(q=st.lists(FLOATS, min_size=29, max_size=29), quat=st.lists(FLOATS, min_size=4, max_size=4),
       gyro=st.lists(FLOATS, min_size=3, max_size=3), temp=st.integers(-32768, 32767),
       mode_machine=st.sampled_from([4, 5, 6, 7, 255]), tick=st.integers(0, 2**32 - 1))
def test_a_crc_valid_state_with_any_values_never_passes_unless_sane(q, quat, gyro, temp, mode_machine, tick):
    msg = LowState(mode_machine=mode_machine, tick=tick)
    msg.motor_q_rad[:29] = q
    msg.imu_quat_wxyz[:] = quat
    msg.imu_gyro_radps[:] = gyro
    msg.motor_temperature_c[:29] = temp
    decoded = LowState.from_dds(msg.to_dds(), verify=True)  # the CRC is valid: only the contents are wrong
    state = lowstate_to_robot_state(decoded, 0.0)
    safety = SafetyFilter()
    safety.expect_mode_machine(5)
    passed = safety.check(state, 0.0)
    if passed:
        assert mode_machine == 5
        assert np.all(np.isfinite(state.q_rad)) and np.all(np.isfinite(state.imu_quat_wxyz))
        assert np.all(state.q_rad >= g1.Q_MIN_RAD - 0.25) and np.all(state.q_rad <= g1.Q_MAX_RAD + 0.25)
        assert abs(np.linalg.norm(state.imu_quat_wxyz) - 1.0) <= 0.1
        assert temp <= safety.config.max_motor_temperature_c
    else:
        assert safety.trip_event is not None and safety.trip_event.trips


def test_remote_round_trip_sanity():
    data = encode_wireless_remote({"A", "start"}, lx=0.5)
    assert decode_wireless_remote(data).buttons == {"A", "start"}
    assert struct.unpack_from("<f", data, 4)[0] == 0.5
