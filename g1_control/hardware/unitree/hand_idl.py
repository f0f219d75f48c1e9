"""Cyclone DDS types of the Dex3-1 hands' messages (`unitree_hg.msg.dds_.HandCmd_` / `HandState_`).

Members and order as docs/robot_facts.md gives them (Unitree SDK's `unitree_hg` definitions):
HandCmd_ {motor_cmd: sequence<MotorCmd_>, reserve: uint32[4]};
HandState_ {motor_state: sequence<MotorState_>, press_sensor_state: sequence<PressSensorState_>,
imu_state: IMUState_, power_v, power_a, system_v, device_v: float32, error: uint32[2],
reserve: uint32[2]}; PressSensorState_ {pressure: float32[12], temperature: float32[12],
lost: uint32, reserve: uint32}. MotorCmd_, MotorState_ and IMUState_ are the body's (idl.py).
Neither message has a crc member, so nothing here computes one. The sequences carry one entry per
motor (7 on a Dex3-1, g1_control/robot/dex3.py). Unlike LowCmd_, these are sent through
IdlStruct.serialize: 7 motors at the hands' rate cost little, and a sequence has no fixed layout
for the numpy codecs. Importing this module needs cyclonedds.
"""

# No `from __future__ import annotations`: Cyclone resolves these annotations at run time.

from dataclasses import dataclass

from cyclonedds.idl import IdlStruct
from cyclonedds.idl.annotations import autoid, final
from cyclonedds.idl.types import array, float32, sequence, uint32

from g1_control.hardware.unitree.idl import IMUState_, MotorCmd_, MotorState_

_HG = "unitree_hg.msg.dds_."

HANDCMD_TYPENAME = _HG + "HandCmd_"
HANDSTATE_TYPENAME = _HG + "HandState_"


@dataclass
@final
@autoid("sequential")
class PressSensorState_(IdlStruct, typename=_HG + "PressSensorState_"):
    pressure: array[float32, 12]
    temperature: array[float32, 12]
    lost: uint32
    reserve: uint32


@dataclass
@final
@autoid("sequential")
class HandCmd_(IdlStruct, typename=HANDCMD_TYPENAME):
    motor_cmd: sequence[MotorCmd_]
    reserve: array[uint32, 4]


@dataclass
@final
@autoid("sequential")
class HandState_(IdlStruct, typename=HANDSTATE_TYPENAME):
    motor_state: sequence[MotorState_]
    press_sensor_state: sequence[PressSensorState_]
    imu_state: IMUState_
    power_v: float32
    power_a: float32
    system_v: float32
    device_v: float32
    error: array[uint32, 2]
    reserve: array[uint32, 2]
