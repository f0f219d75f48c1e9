"""FingerCommand / FingerState <-> the Dex3-1 DDS samples (HandCmd_ / HandState_, hand_idl.py).

Each motor's mode byte carries its index and enable status (g1_control/robot/dex3.py); a state
whose motor_state sequence does not hold exactly 7 entries is refused with MalformedMessageError
(another hand model, or another message on the topic). Importing this module needs cyclonedds.
"""

from __future__ import annotations

import numpy as np

from g1_control.errors import MalformedMessageError
from g1_control.hardware.unitree.hand_idl import HandCmd_, HandState_, PressSensorState_
from g1_control.hardware.unitree.idl import IMUState_, MotorCmd_, MotorState_
from g1_control.robot import dex3
from g1_control.types import FingerCommand, FingerState


def finger_command_to_handcmd(command: FingerCommand) -> HandCmd_:
    """The HandCmd_ sample of `command` (7 MotorCmd_, each with its index and enable bit)."""
    motors = [
        MotorCmd_(mode=dex3.motor_mode(i, bool(command.enable[i])), q=float(command.q_rad[i]),
                  dq=float(command.dq_radps[i]), tau=float(command.tau_nm[i]), kp=float(command.kp[i]),
                  kd=float(command.kd[i]), reserve=0)
        for i in range(dex3.NUM_MOTORS)
    ]
    return HandCmd_(motor_cmd=motors, reserve=[0, 0, 0, 0])


def handcmd_to_finger_command(msg: HandCmd_) -> FingerCommand:
    """What a hand does with a HandCmd_ (the emulator's side). Raises MalformedMessageError unless
    it holds 7 motor commands."""
    _check_count("HandCmd_.motor_cmd", len(msg.motor_cmd))
    m = msg.motor_cmd
    return FingerCommand(
        q_rad=np.array([c.q for c in m], dtype=float), dq_radps=np.array([c.dq for c in m], dtype=float),
        kp=np.array([c.kp for c in m], dtype=float), kd=np.array([c.kd for c in m], dtype=float),
        tau_nm=np.array([c.tau for c in m], dtype=float),
        enable=np.array([dex3.mode_enabled(c.mode) for c in m], dtype=bool))


def finger_state_to_handstate(state: FingerState, pressure: np.ndarray | None = None) -> HandState_:
    """The HandState_ a hand reports for `state` (the emulator's side). pressure: (n, 12) pad
    readings, one PressSensorState_ per row (none when None)."""
    motors = [
        MotorState_(mode=dex3.motor_mode(i, bool(state.motor_enabled[i])), q=float(state.q_rad[i]),
                    dq=float(state.dq_radps[i]), ddq=0.0, tau_est=float(state.tau_nm[i]),
                    temperature=[int(state.temperature_c[i])] * 2, vol=float(state.power_v), sensor=[0, 0],
                    motorstate=0, reserve=[0, 0, 0, 0])
        for i in range(dex3.NUM_MOTORS)
    ]
    pads = [] if pressure is None else [
        PressSensorState_(pressure=[float(v) for v in row], temperature=[0.0] * 12, lost=0, reserve=0)
        for row in np.atleast_2d(pressure)]
    imu = IMUState_(quaternion=[1.0, 0.0, 0.0, 0.0], gyroscope=[0.0] * 3, accelerometer=[0.0] * 3, rpy=[0.0] * 3,
                    temperature=0)
    return HandState_(motor_state=motors, press_sensor_state=pads, imu_state=imu, power_v=float(state.power_v),
                      power_a=float(state.power_a), system_v=float(state.power_v), device_v=float(state.power_v),
                      error=list(state.error), reserve=[0, 0])


def handstate_to_finger_state(msg: HandState_, t_s: float) -> FingerState:
    """The host's reading of a HandState_ received at `t_s`. Raises MalformedMessageError unless it
    holds 7 motor states."""
    _check_count("HandState_.motor_state", len(msg.motor_state))
    m = msg.motor_state
    return FingerState(
        q_rad=np.array([s.q for s in m], dtype=float), dq_radps=np.array([s.dq for s in m], dtype=float),
        tau_nm=np.array([s.tau_est for s in m], dtype=float),
        temperature_c=np.array([max(s.temperature) for s in m], dtype=float),
        motor_enabled=np.array([dex3.mode_enabled(s.mode) for s in m], dtype=bool),
        power_v=float(msg.power_v), power_a=float(msg.power_a), error=(int(msg.error[0]), int(msg.error[1])),
        t_s=t_s)


def _check_count(what: str, n: int) -> None:
    if n != dex3.NUM_MOTORS:
        raise MalformedMessageError(f"{what} holds {n} entries; a Dex3-1 hand has {dex3.NUM_MOTORS} motors "
                                    "(another hand model, or another message on this topic)")
