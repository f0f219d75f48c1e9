"""The G1's low-level messages (`unitree_hg.msg.dds_.LowCmd_` / `LowState_`), defined by this
project from the protocol (see docs/robot_facts.md), with fast numpy codecs for both byte forms:

- `to_dds` / `from_dds`: the XCDR1 little-endian sample DDS carries (4-byte encapsulation header
  + payload), byte-identical to what Unitree's own type definitions serialise to;
- `to_c_bytes` / `from_c_bytes`: the C struct memory image (4-byte alignment; LowCmd_ 1004 bytes,
  LowState_ 2092 bytes) that the CRC covers and that the CAN/serial links carry.

The CRC is the last 32-bit word of the C image, computed over every word before it.
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields
from typing import Any, ClassVar

import numpy as np

from g1_control.errors import CrcMismatchError, MalformedMessageError
from g1_control.hardware.unitree.crc import crc32_words
from g1_control.hardware.unitree.layout import F32, I16, U8, U32, FieldCodec, Struct, flatten
from g1_control.robot.g1 import NUM_MOTOR_SLOTS

LOWCMD_TYPENAME = "unitree_hg.msg.dds_.LowCmd_"
LOWSTATE_TYPENAME = "unitree_hg.msg.dds_.LowState_"
LOWCMD_TOPIC = "rt/lowcmd"
LOWSTATE_TOPIC = "rt/lowstate"

MOTOR_CMD = Struct("MotorCmd_", (
    ("mode", U8, 1), ("q", F32, 1), ("dq", F32, 1), ("tau", F32, 1),
    ("kp", F32, 1), ("kd", F32, 1), ("reserve", U32, 1),
))
LOW_CMD = Struct("LowCmd_", (
    ("mode_pr", U8, 1), ("mode_machine", U8, 1), ("motor_cmd", MOTOR_CMD, NUM_MOTOR_SLOTS),
    ("reserve", U32, 4), ("crc", U32, 1),
))
IMU_STATE = Struct("IMUState_", (
    ("quaternion", F32, 4), ("gyroscope", F32, 3), ("accelerometer", F32, 3), ("rpy", F32, 3),
    ("temperature", I16, 1),
))
MOTOR_STATE = Struct("MotorState_", (
    ("mode", U8, 1), ("q", F32, 1), ("dq", F32, 1), ("ddq", F32, 1), ("tau_est", F32, 1),
    ("temperature", I16, 2), ("vol", F32, 1), ("sensor", U32, 2), ("motorstate", U32, 1),
    ("reserve", U32, 4),
))
LOW_STATE = Struct("LowState_", (
    ("version", U32, 2), ("mode_pr", U8, 1), ("mode_machine", U8, 1), ("tick", U32, 1),
    ("imu_state", IMU_STATE, 1), ("motor_state", MOTOR_STATE, NUM_MOTOR_SLOTS),
    ("wireless_remote", U8, 40), ("reserve", U32, 4), ("crc", U32, 1),
))

# XCDR1, little endian (representation id 0x0001, options 0), as Cyclone DDS writes it.
DDS_HEADER = b"\x00\x01\x00\x00"
_DDS_HEADERS_ACCEPTED = (DDS_HEADER, b"\x00\x07\x00\x00")  # XCDR2 LE: same payload for these types

_CMD_C = FieldCodec(flatten(LOW_CMD, "c"))
_CMD_DDS = FieldCodec(flatten(LOW_CMD, "xcdr1"), base=4)
_STATE_C = FieldCodec(flatten(LOW_STATE, "c"))
_STATE_DDS = FieldCodec(flatten(LOW_STATE, "xcdr1"), base=4)



def _c_from_dds(c: FieldCodec, dds: FieldCodec) -> np.ndarray:
    """Index that gathers the C image from a DDS sample buffer (padding reads a zero byte placed
    one past the sample), so the CRC of a sample costs one gather instead of a second packing."""
    zero = dds.buffer_size
    index = np.full(c.size, zero, dtype=np.intp)
    for path, leaf in c.layout.leaves.items():
        size = leaf.primitive.size
        src = dds.layout.leaves[path].offsets.ravel() + dds.base
        dst = leaf.offsets.ravel()
        for k in range(size):
            index[dst + k] = src + k
    return index


_CMD_GATHER = _c_from_dds(_CMD_C, _CMD_DDS)
_STATE_GATHER = _c_from_dds(_STATE_C, _STATE_DDS)

LOWCMD_C_SIZE = _CMD_C.size
LOWSTATE_C_SIZE = _STATE_C.size
LOWCMD_DDS_SIZE = _CMD_DDS.size
LOWSTATE_DDS_SIZE = _STATE_DDS.size


def _slots(dtype) -> np.ndarray:
    return np.zeros(NUM_MOTOR_SLOTS, dtype=dtype)


class _Message:
    """Encoding shared by LowCmd and LowState; each sets its layouts and names as class attributes."""

    _C: ClassVar[FieldCodec]
    _DDS: ClassVar[FieldCodec]
    _GATHER: ClassVar[np.ndarray]
    _IDL_NAME: ClassVar[str]

    def to_c_bytes(self, with_crc: bool = True) -> bytes:
        """The C struct image (LowCmd_ 1004 bytes); with_crc stores the freshly computed CRC in it."""
        buf = _pack(self, self._C)
        if with_crc:
            self.crc = _seal(buf)
        return buf.tobytes()

    def to_dds(self) -> bytes:
        """The DDS sample, with the CRC recomputed over the current contents."""
        return _seal_dds(self, self._DDS, self._GATHER)

    @classmethod
    def from_dds(cls, data: bytes, verify: bool = False):
        """Decode a DDS sample; verify=True raises CrcMismatchError for a bad CRC."""
        buf = _check_dds(data, cls._DDS, cls._IDL_NAME)
        if verify:
            _verify_gathered(buf, cls._DDS, cls._GATHER, cls.__name__)
        return _unpack(cls, cls._DDS, buf)

    @classmethod
    def from_c_bytes(cls, data: bytes, verify: bool = False):
        buf = _check_c(data, cls._C, cls._IDL_NAME)
        if verify:
            _verify_image(buf, cls._C.size, cls.__name__)
        return _unpack(cls, cls._C, buf)


@dataclass
class LowCmd(_Message):
    """LowCmd_: one command for all 35 motor slots (the G1 uses the first 29)."""

    mode_pr: int = 0
    """0: ankle/waist commanded as pitch/roll joints; 1: as the parallel motors A/B."""
    mode_machine: int = 0
    """Must echo LowState.mode_machine, or the robot ignores the command."""
    motor_mode: np.ndarray = field(default_factory=lambda: _slots(np.uint8))
    """1 = motor enabled, 0 = disabled (no torque)."""
    motor_q_rad: np.ndarray = field(default_factory=lambda: _slots(np.float32))
    motor_dq_radps: np.ndarray = field(default_factory=lambda: _slots(np.float32))
    motor_tau_nm: np.ndarray = field(default_factory=lambda: _slots(np.float32))
    motor_kp_nm_per_rad: np.ndarray = field(default_factory=lambda: _slots(np.float32))
    motor_kd_nms_per_rad: np.ndarray = field(default_factory=lambda: _slots(np.float32))
    motor_reserve: np.ndarray = field(default_factory=lambda: _slots(np.uint32))
    reserve: np.ndarray = field(default_factory=lambda: np.zeros(4, dtype=np.uint32))
    crc: int = 0

    _PATHS: ClassVar[dict[str, str]] = {
        "mode_pr": "mode_pr", "mode_machine": "mode_machine",
        "motor_mode": "motor_cmd.mode", "motor_q_rad": "motor_cmd.q", "motor_dq_radps": "motor_cmd.dq",
        "motor_tau_nm": "motor_cmd.tau", "motor_kp_nm_per_rad": "motor_cmd.kp",
        "motor_kd_nms_per_rad": "motor_cmd.kd", "motor_reserve": "motor_cmd.reserve",
        "reserve": "reserve", "crc": "crc",
    }

    _C: ClassVar[FieldCodec] = _CMD_C
    _DDS: ClassVar[FieldCodec] = _CMD_DDS
    _GATHER: ClassVar[np.ndarray] = _CMD_GATHER
    _IDL_NAME: ClassVar[str] = "LowCmd_"


@dataclass
class LowState(_Message):
    """LowState_: what the robot reports at 500 Hz."""

    version: np.ndarray = field(default_factory=lambda: np.zeros(2, dtype=np.uint32))
    mode_pr: int = 0
    mode_machine: int = 0
    tick: int = 0
    imu_quat_wxyz: np.ndarray = field(default_factory=lambda: np.array([1, 0, 0, 0], dtype=np.float32))
    imu_gyro_radps: np.ndarray = field(default_factory=lambda: np.zeros(3, dtype=np.float32))
    imu_acc_mps2: np.ndarray = field(default_factory=lambda: np.zeros(3, dtype=np.float32))
    imu_rpy_rad: np.ndarray = field(default_factory=lambda: np.zeros(3, dtype=np.float32))
    imu_temperature_c: int = 0
    motor_mode: np.ndarray = field(default_factory=lambda: _slots(np.uint8))
    motor_q_rad: np.ndarray = field(default_factory=lambda: _slots(np.float32))
    motor_dq_radps: np.ndarray = field(default_factory=lambda: _slots(np.float32))
    motor_ddq_radps2: np.ndarray = field(default_factory=lambda: _slots(np.float32))
    motor_tau_est_nm: np.ndarray = field(default_factory=lambda: _slots(np.float32))
    motor_temperature_c: np.ndarray = field(default_factory=lambda: np.zeros((NUM_MOTOR_SLOTS, 2), dtype=np.int16))
    """Two sensors per motor (Unitree does not document which is which; the safety layer uses the max)."""
    motor_voltage_v: np.ndarray = field(default_factory=lambda: _slots(np.float32))
    motor_sensor: np.ndarray = field(default_factory=lambda: np.zeros((NUM_MOTOR_SLOTS, 2), dtype=np.uint32))
    motor_state_flags: np.ndarray = field(default_factory=lambda: _slots(np.uint32))
    motor_reserve: np.ndarray = field(default_factory=lambda: np.zeros((NUM_MOTOR_SLOTS, 4), dtype=np.uint32))
    wireless_remote: bytes = bytes(40)
    reserve: np.ndarray = field(default_factory=lambda: np.zeros(4, dtype=np.uint32))
    crc: int = 0

    _PATHS: ClassVar[dict[str, str]] = {
        "version": "version", "mode_pr": "mode_pr", "mode_machine": "mode_machine", "tick": "tick",
        "imu_quat_wxyz": "imu_state.quaternion", "imu_gyro_radps": "imu_state.gyroscope",
        "imu_acc_mps2": "imu_state.accelerometer", "imu_rpy_rad": "imu_state.rpy",
        "imu_temperature_c": "imu_state.temperature",
        "motor_mode": "motor_state.mode", "motor_q_rad": "motor_state.q", "motor_dq_radps": "motor_state.dq",
        "motor_ddq_radps2": "motor_state.ddq", "motor_tau_est_nm": "motor_state.tau_est",
        "motor_temperature_c": "motor_state.temperature", "motor_voltage_v": "motor_state.vol",
        "motor_sensor": "motor_state.sensor", "motor_state_flags": "motor_state.motorstate",
        "motor_reserve": "motor_state.reserve", "wireless_remote": "wireless_remote",
        "reserve": "reserve", "crc": "crc",
    }

    _C: ClassVar[FieldCodec] = _STATE_C
    _DDS: ClassVar[FieldCodec] = _STATE_DDS
    _GATHER: ClassVar[np.ndarray] = _STATE_GATHER
    _IDL_NAME: ClassVar[str] = "LowState_"


def compute_crc(msg: LowCmd | LowState) -> int:
    """The CRC the robot expects in `msg.crc` for the current contents (msg.crc itself excluded)."""
    codec = _CMD_C if isinstance(msg, LowCmd) else _STATE_C
    buf = _pack(msg, codec)
    return crc32_words(buf[: codec.size - 4])


def verify_crc(msg: LowCmd | LowState) -> None:
    """Raise CrcMismatchError unless msg.crc matches its contents."""
    expected = compute_crc(msg)
    if int(msg.crc) != expected:
        raise _mismatch(type(msg).__name__, int(msg.crc), expected)


def _mismatch(name: str, got: int, expected: int) -> CrcMismatchError:
    return CrcMismatchError(
        f"{name} CRC is 0x{got:08x} but its contents give 0x{expected:08x}; "
        "the sample was corrupted or built by a sender that does not compute the G1 CRC"
    )


def _seal_dds(msg, codec: FieldCodec, gather: np.ndarray) -> bytes:
    msg.crc = 0
    full = np.zeros(codec.buffer_size + 1, dtype=np.uint8)  # +1: the zero byte padding gathers
    buf = full[: codec.buffer_size]
    _fill(msg, codec, buf, DDS_HEADER)
    msg.crc = crc32_words(full[gather][:-4])
    codec.put(buf, "crc", msg.crc)
    return buf[: codec.size].tobytes()


def _verify_gathered(buf: np.ndarray, codec: FieldCodec, gather: np.ndarray, name: str) -> None:
    full = np.zeros(codec.buffer_size + 1, dtype=np.uint8)
    full[: buf.size] = buf
    expected = crc32_words(full[gather][:-4])
    got = int(codec.get(buf, "crc"))
    if got != expected:
        raise _mismatch(name, got, expected)


def _verify_image(buf: np.ndarray, size: int, name: str) -> None:
    expected = crc32_words(buf[: size - 4])
    got = int(buf[size - 4: size].view("<u4")[0])
    if got != expected:
        raise _mismatch(name, got, expected)


def _seal(buf: np.ndarray) -> int:
    crc = crc32_words(buf[:-4])
    buf[-4:].view("<u4")[0] = crc
    return crc


def _pack(msg, codec: FieldCodec, header: bytes = b"") -> np.ndarray:
    buf = np.zeros(codec.buffer_size, dtype=np.uint8)
    _fill(msg, codec, buf, header)
    return buf[: codec.size]


def _fill(msg, codec: FieldCodec, buf: np.ndarray, header: bytes = b"") -> None:
    if header:
        buf[: len(header)] = np.frombuffer(header, dtype=np.uint8)
    for attr, path in msg._PATHS.items():
        value = getattr(msg, attr)
        if isinstance(value, (bytes, bytearray)):
            value = np.frombuffer(value, dtype=np.uint8)
        codec.put(buf, path, value)


def _unpack(cls, codec: FieldCodec, buf: np.ndarray):
    kwargs: dict[str, Any] = {}
    scalar_types = {f.name: f.type for f in fields(cls)}
    for attr, path in cls._PATHS.items():
        value = codec.get(buf, path)
        if attr == "wireless_remote":
            kwargs[attr] = value.tobytes()
        elif value.ndim == 0 or scalar_types[attr] == "int":
            kwargs[attr] = int(value)
        else:
            kwargs[attr] = value
    return cls(**kwargs)


def _as_buffer(data: bytes, size: int) -> np.ndarray:
    buf = np.zeros((size + 3) // 4 * 4, dtype=np.uint8)
    buf[:size] = np.frombuffer(data, dtype=np.uint8, count=size)
    return buf


def _check_dds(data: bytes, codec: FieldCodec, name: str) -> np.ndarray:
    if len(data) < codec.size:
        raise MalformedMessageError(
            f"{name} sample is {len(data)} bytes; a complete one is {codec.size} "
            "(truncated sample, or another message type on this topic)"
        )
    if bytes(data[:4]) not in _DDS_HEADERS_ACCEPTED:
        raise MalformedMessageError(
            f"{name} sample starts with encapsulation {bytes(data[:4]).hex()}; expected little-endian "
            "CDR (0001 or 0007): the sender is not a G1 or uses a big-endian encoding"
        )
    return _as_buffer(data, codec.size)


def _check_c(data: bytes, codec: FieldCodec, name: str) -> np.ndarray:
    if len(data) != codec.size:
        raise MalformedMessageError(f"{name} image is {len(data)} bytes; expected exactly {codec.size}")
    return _as_buffer(data, codec.size)
