"""The project's own G1 message definitions against Unitree's official ones, byte for byte."""

from __future__ import annotations

import numpy as np
import pytest

from g1_control.errors import CrcMismatchError, MalformedMessageError
from g1_control.hardware.unitree import messages as hgm
from g1_control.hardware.unitree.crc import crc32_words, crc32_words_table
from tests.hardware.unitree_reference import crc32_bitwise, hg, official_crc

RNG = np.random.default_rng(5)


def _random_f32(n, rng):
    # Ordinary values plus the awkward ones a wire format must carry unchanged.
    values = rng.normal(0.0, 3.0, n).astype(np.float32)
    values[rng.integers(0, n)] = np.float32(-0.0)
    values[rng.integers(0, n)] = np.finfo(np.float32).max
    return values


def random_lowcmd(rng) -> hgm.LowCmd:
    return hgm.LowCmd(
        mode_pr=int(rng.integers(0, 2)),
        mode_machine=int(rng.integers(0, 256)),
        motor_mode=rng.integers(0, 256, 35).astype(np.uint8),
        motor_q_rad=_random_f32(35, rng),
        motor_dq_radps=_random_f32(35, rng),
        motor_tau_nm=_random_f32(35, rng),
        motor_kp_nm_per_rad=_random_f32(35, rng),
        motor_kd_nms_per_rad=_random_f32(35, rng),
        motor_reserve=rng.integers(0, 2**32, 35, dtype=np.uint64).astype(np.uint32),
        reserve=rng.integers(0, 2**32, 4, dtype=np.uint64).astype(np.uint32),
    )


def random_lowstate(rng) -> hgm.LowState:
    return hgm.LowState(
        version=rng.integers(0, 2**32, 2, dtype=np.uint64).astype(np.uint32),
        mode_pr=int(rng.integers(0, 2)),
        mode_machine=int(rng.integers(0, 256)),
        tick=int(rng.integers(0, 2**32)),
        imu_quat_wxyz=_random_f32(4, rng),
        imu_gyro_radps=_random_f32(3, rng),
        imu_acc_mps2=_random_f32(3, rng),
        imu_rpy_rad=_random_f32(3, rng),
        imu_temperature_c=int(rng.integers(-2**15, 2**15)),
        motor_mode=rng.integers(0, 256, 35).astype(np.uint8),
        motor_q_rad=_random_f32(35, rng),
        motor_dq_radps=_random_f32(35, rng),
        motor_ddq_radps2=_random_f32(35, rng),
        motor_tau_est_nm=_random_f32(35, rng),
        motor_temperature_c=rng.integers(-2**15, 2**15, (35, 2)).astype(np.int16),
        motor_voltage_v=_random_f32(35, rng),
        motor_sensor=rng.integers(0, 2**32, (35, 2), dtype=np.uint64).astype(np.uint32),
        motor_state_flags=rng.integers(0, 2**32, 35, dtype=np.uint64).astype(np.uint32),
        motor_reserve=rng.integers(0, 2**32, (35, 4), dtype=np.uint64).astype(np.uint32),
        wireless_remote=rng.integers(0, 256, 40).astype(np.uint8).tobytes(),
        reserve=rng.integers(0, 2**32, 4, dtype=np.uint64).astype(np.uint32),
    )


def official_lowcmd(msg: hgm.LowCmd):
    motors = [
        hg.MotorCmd_(mode=int(msg.motor_mode[i]), q=float(msg.motor_q_rad[i]), dq=float(msg.motor_dq_radps[i]),
                     tau=float(msg.motor_tau_nm[i]), kp=float(msg.motor_kp_nm_per_rad[i]),
                     kd=float(msg.motor_kd_nms_per_rad[i]), reserve=int(msg.motor_reserve[i]))
        for i in range(35)
    ]
    return hg.LowCmd_(mode_pr=msg.mode_pr, mode_machine=msg.mode_machine, motor_cmd=motors,
                      reserve=[int(v) for v in msg.reserve], crc=int(msg.crc))


def official_lowstate(msg: hgm.LowState):
    imu = hg.IMUState_(
        quaternion=[float(v) for v in msg.imu_quat_wxyz], gyroscope=[float(v) for v in msg.imu_gyro_radps],
        accelerometer=[float(v) for v in msg.imu_acc_mps2], rpy=[float(v) for v in msg.imu_rpy_rad],
        temperature=int(msg.imu_temperature_c),
    )
    motors = [
        hg.MotorState_(
            mode=int(msg.motor_mode[i]), q=float(msg.motor_q_rad[i]), dq=float(msg.motor_dq_radps[i]),
            ddq=float(msg.motor_ddq_radps2[i]), tau_est=float(msg.motor_tau_est_nm[i]),
            temperature=[int(v) for v in msg.motor_temperature_c[i]], vol=float(msg.motor_voltage_v[i]),
            sensor=[int(v) for v in msg.motor_sensor[i]], motorstate=int(msg.motor_state_flags[i]),
            reserve=[int(v) for v in msg.motor_reserve[i]],
        )
        for i in range(35)
    ]
    return hg.LowState_(version=[int(v) for v in msg.version], mode_pr=msg.mode_pr, mode_machine=msg.mode_machine,
                        tick=msg.tick, imu_state=imu, motor_state=motors,
                        wireless_remote=list(msg.wireless_remote), reserve=[int(v) for v in msg.reserve],
                        crc=int(msg.crc))


def test_sizes_match_the_protocol():
    assert hgm.LOWCMD_C_SIZE == 1004
    assert hgm.LOWSTATE_C_SIZE == 2092
    assert hgm.LOWCMD_DDS_SIZE == len(hg.LowCmd_(0, 0, [hg.MotorCmd_(0, 0, 0, 0, 0, 0, 0)] * 35, [0] * 4, 0).serialize())


@pytest.mark.parametrize("seed", range(6))
def test_lowcmd_dds_bytes_and_crc_equal_official(seed):
    rng = np.random.default_rng(seed)
    ours = random_lowcmd(rng)
    wire = ours.to_dds()  # sets ours.crc
    official = official_lowcmd(ours)
    assert wire == official.serialize()
    assert ours.crc == official_crc(official)
    back = hgm.LowCmd.from_dds(wire)
    assert back.to_dds() == wire
    assert type(back).from_dds(official.serialize()).crc == ours.crc


@pytest.mark.parametrize("seed", range(6))
def test_lowstate_dds_bytes_and_crc_equal_official(seed):
    rng = np.random.default_rng(100 + seed)
    ours = random_lowstate(rng)
    wire = ours.to_dds()
    official = official_lowstate(ours)
    assert wire == official.serialize()
    assert ours.crc == official_crc(official)
    decoded = hg.LowState_.deserialize(wire)
    assert list(decoded.wireless_remote) == list(ours.wireless_remote)
    back = hgm.LowState.from_dds(wire)
    np.testing.assert_array_equal(back.motor_temperature_c, ours.motor_temperature_c)
    assert back.wireless_remote == ours.wireless_remote
    assert back.to_dds() == wire


def test_c_image_round_trip_carries_the_crc_in_its_last_word():
    msg = random_lowcmd(RNG)
    image = msg.to_c_bytes()
    assert len(image) == 1004
    assert int.from_bytes(image[-4:], "little") == msg.crc == crc32_bitwise(
        np.frombuffer(image[:-4], dtype="<u4"))
    back = hgm.LowCmd.from_c_bytes(image)
    hgm.verify_crc(back)
    np.testing.assert_array_equal(back.motor_kd_nms_per_rad, msg.motor_kd_nms_per_rad)


def test_fast_crc_equals_table_and_bitwise_reference():
    for n_words in (1, 2, 7, 250):
        words = RNG.integers(0, 2**32, n_words, dtype=np.uint64).astype("<u4")
        expected = crc32_bitwise(words)
        assert crc32_words(words.tobytes()) == expected
        assert crc32_words_table(words) == expected


def test_crc_catches_a_single_flipped_bit():
    msg = random_lowcmd(RNG)
    wire = bytearray(msg.to_dds())
    wire[40] ^= 0x01
    with pytest.raises(CrcMismatchError, match="LowCmd CRC is 0x"):
        hgm.verify_crc(hgm.LowCmd.from_dds(bytes(wire)))
    with pytest.raises(CrcMismatchError, match="LowCmd CRC is 0x.*corrupted"):
        hgm.LowCmd.from_dds(bytes(wire), verify=True)
    hgm.LowCmd.from_dds(msg.to_dds(), verify=True)


def test_verified_decoding_of_both_forms_and_both_messages():
    state = random_lowstate(RNG)
    wire, image = state.to_dds(), state.to_c_bytes()
    assert hgm.LowState.from_dds(wire, verify=True).crc == hgm.LowState.from_c_bytes(image, verify=True).crc
    bad_image = bytearray(image)
    bad_image[100] ^= 0x80
    with pytest.raises(CrcMismatchError, match="LowState CRC"):
        hgm.LowState.from_c_bytes(bytes(bad_image), verify=True)
    bad_wire = bytearray(wire)
    bad_wire[-1] ^= 0x01  # inside the CRC word itself
    with pytest.raises(CrcMismatchError):
        hgm.LowState.from_dds(bytes(bad_wire), verify=True)


def test_short_and_foreign_samples_are_refused_by_name():
    wire = hgm.LowState().to_dds()
    with pytest.raises(MalformedMessageError, match="LowState_ sample is 100 bytes; a complete one is 2092"):
        hgm.LowState.from_dds(wire[:100])
    with pytest.raises(MalformedMessageError, match="encapsulation 0000"):
        hgm.LowState.from_dds(b"\x00\x00\x00\x00" + wire[4:])
    with pytest.raises(MalformedMessageError, match="expected exactly 1004"):
        hgm.LowCmd.from_c_bytes(b"\x00" * 1000)


def test_crc_input_must_be_whole_words():
    with pytest.raises(ValueError, match="whole 32-bit words; got 3 bytes"):
        crc32_words(b"abc")


def test_our_dds_type_declarations_serialise_like_unitrees():
    from g1_control.hardware.unitree import idl as ours
    from tests.hardware.unitree_reference import api

    msg = random_lowcmd(RNG)
    wire = msg.to_dds()
    assert ours.LowCmd_.deserialize(wire).serialize() == wire
    state_wire = random_lowstate(RNG).to_dds()
    assert ours.LowState_.deserialize(state_wire).serialize() == state_wire

    def request(mod):
        header = mod.RequestHeader_(mod.RequestIdentity_(123456789012, 1003), mod.RequestLease_(7),
                                    mod.RequestPolicy_(2, False))
        return mod.Request_(header, '{"name":"ai"}', [1, 2, 3])

    def response(mod):
        header = mod.ResponseHeader_(mod.RequestIdentity_(123456789012, 1001), mod.ResponseStatus_(3203))
        return mod.Response_(header, '{"form":"0","name":""}', [])

    assert request(ours).serialize() == request(api).serialize()
    assert response(ours).serialize() == response(api).serialize()
    assert ours.Request_.__idl_typename__ == api.Request_.__idl_typename__ == "unitree_api.msg.dds_.Request_"
