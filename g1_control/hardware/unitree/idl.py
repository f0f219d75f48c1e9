"""Cyclone DDS type declarations of the G1 topics, for topic registration and type matching.

The byte layout of LowCmd_/LowState_ lives in unitree_hg.py (numpy codecs, what is actually sent);
these classes give Cyclone the type names and member structure the robot announces, so that
discovery matches. Member names and order follow the protocol (docs/robot_facts.md); tests check that
they serialise to the same bytes as the numpy codecs and as Unitree's own definitions.
Importing this module needs cyclonedds (scripts/install_cyclonedds.sh).
"""

# No `from __future__ import annotations`: Cyclone resolves these annotations at run time.

from dataclasses import dataclass

from cyclonedds.idl import IdlStruct
from cyclonedds.idl.annotations import autoid, final
from cyclonedds.idl.types import array, float32, int16, int32, int64, sequence, uint8, uint32

_HG = "unitree_hg.msg.dds_."
_API = "unitree_api.msg.dds_."


@dataclass
@final
@autoid("sequential")
class MotorCmd_(IdlStruct, typename=_HG + "MotorCmd_"):
    mode: uint8
    q: float32
    dq: float32
    tau: float32
    kp: float32
    kd: float32
    reserve: uint32


@dataclass
@final
@autoid("sequential")
class LowCmd_(IdlStruct, typename=_HG + "LowCmd_"):
    mode_pr: uint8
    mode_machine: uint8
    motor_cmd: array[MotorCmd_, 35]
    reserve: array[uint32, 4]
    crc: uint32


@dataclass
@final
@autoid("sequential")
class IMUState_(IdlStruct, typename=_HG + "IMUState_"):
    quaternion: array[float32, 4]
    gyroscope: array[float32, 3]
    accelerometer: array[float32, 3]
    rpy: array[float32, 3]
    temperature: int16


@dataclass
@final
@autoid("sequential")
class MotorState_(IdlStruct, typename=_HG + "MotorState_"):
    mode: uint8
    q: float32
    dq: float32
    ddq: float32
    tau_est: float32
    temperature: array[int16, 2]
    vol: float32
    sensor: array[uint32, 2]
    motorstate: uint32
    reserve: array[uint32, 4]


@dataclass
@final
@autoid("sequential")
class LowState_(IdlStruct, typename=_HG + "LowState_"):
    version: array[uint32, 2]
    mode_pr: uint8
    mode_machine: uint8
    tick: uint32
    imu_state: IMUState_
    motor_state: array[MotorState_, 35]
    wireless_remote: array[uint8, 40]
    reserve: array[uint32, 4]
    crc: uint32


# Unitree's request/response RPC envelope (used here for the motion-switcher service).
@dataclass
@final
@autoid("sequential")
class RequestIdentity_(IdlStruct, typename=_API + "RequestIdentity_"):
    id: int64
    api_id: int64


@dataclass
@final
@autoid("sequential")
class RequestLease_(IdlStruct, typename=_API + "RequestLease_"):
    id: int64


@dataclass
@final
@autoid("sequential")
class RequestPolicy_(IdlStruct, typename=_API + "RequestPolicy_"):
    priority: int32
    noreply: bool


@dataclass
@final
@autoid("sequential")
class RequestHeader_(IdlStruct, typename=_API + "RequestHeader_"):
    identity: RequestIdentity_
    lease: RequestLease_
    policy: RequestPolicy_


@dataclass
@final
@autoid("sequential")
class Request_(IdlStruct, typename=_API + "Request_"):
    header: RequestHeader_
    parameter: str
    binary: sequence[uint8]


@dataclass
@final
@autoid("sequential")
class ResponseStatus_(IdlStruct, typename=_API + "ResponseStatus_"):
    code: int32


@dataclass
@final
@autoid("sequential")
class ResponseHeader_(IdlStruct, typename=_API + "ResponseHeader_"):
    identity: RequestIdentity_
    status: ResponseStatus_


@dataclass
@final
@autoid("sequential")
class Response_(IdlStruct, typename=_API + "Response_"):
    header: ResponseHeader_
    data: str
    binary: sequence[uint8]
