"""LowState_ <-> RobotState and MotorCommand <-> LowCmd_: the only place robot slots meet joints.

The G1 keeps the 29-DoF slot numbering on every variant; a 23-DoF robot (mode_machine 4) simply
has no motor behind the waist roll/pitch and wrist pitch/yaw slots, and a locked-waist one
(mode_machine 6) none behind waist roll/pitch. Commands for slots without a motor, and for slots
29-34, go out disabled with zero gains so a variant mismatch can never drive a phantom joint.
"""

from __future__ import annotations

import numpy as np

from g1_control.errors import VariantMismatchError
from g1_control.hardware.unitree.messages import LowCmd, LowState
from g1_control.robot import g1
from g1_control.types import MotorCommand, RobotState

MOTOR_ENABLED = 1
MOTOR_DISABLED = 0


def variant_of(mode_machine: int) -> g1.Variant:
    """The G1 variant behind `mode_machine`, or VariantMismatchError naming the known ones."""
    try:
        return g1.variant_for_mode_machine(int(mode_machine))
    except ValueError as exc:
        raise VariantMismatchError(
            f"the robot reports mode_machine {mode_machine}, which is no G1 variant this project knows "
            f"({exc}); check that the robot is a G1 and its firmware is supported"
        ) from None


def lowstate_to_robot_state(msg: LowState, t_s: float) -> RobotState:
    """RobotState stamped `t_s` (the receiver's clock: the safety layer measures staleness with it)."""
    n = g1.NUM_JOINTS
    return RobotState(
        t_s=float(t_s),
        q_rad=msg.motor_q_rad[:n].astype(np.float64),
        dq_radps=msg.motor_dq_radps[:n].astype(np.float64),
        tau_nm=msg.motor_tau_est_nm[:n].astype(np.float64),
        imu_quat_wxyz=msg.imu_quat_wxyz.astype(np.float64),
        imu_gyro_radps=msg.imu_gyro_radps.astype(np.float64),
        imu_acc_mps2=msg.imu_acc_mps2.astype(np.float64),
        motor_temperature_c=msg.motor_temperature_c[:n].max(axis=1).astype(np.float64),
        mode_machine=int(msg.mode_machine),
        tick=int(msg.tick),
        wireless_remote=bytes(msg.wireless_remote),
    )


def robot_state_to_lowstate(state: RobotState, mode_pr: int = 0) -> LowState:
    """What a robot (or an emulator of one) reports for `state`; the CRC is set when encoding."""
    n = g1.NUM_JOINTS
    msg = LowState(mode_pr=mode_pr, mode_machine=int(state.mode_machine), tick=int(state.tick) & 0xFFFFFFFF)
    msg.imu_quat_wxyz[:] = state.imu_quat_wxyz
    msg.imu_gyro_radps[:] = state.imu_gyro_radps
    msg.imu_acc_mps2[:] = state.imu_acc_mps2
    active = variant_of(state.mode_machine).active_mask
    msg.motor_mode[:n] = np.where(active, MOTOR_ENABLED, MOTOR_DISABLED)
    msg.motor_q_rad[:n] = state.q_rad
    msg.motor_dq_radps[:n] = state.dq_radps
    msg.motor_tau_est_nm[:n] = state.tau_nm
    temperature = np.clip(np.round(state.motor_temperature_c), -32768, 32767).astype(np.int16)
    msg.motor_temperature_c[:n] = temperature[:, None]
    remote = bytes(state.wireless_remote)[:40]
    msg.wireless_remote = remote + bytes(40 - len(remote))
    return msg


def motor_command_to_lowcmd(command: MotorCommand, mode_machine: int, mode_pr: int = 0,
                            out: LowCmd | None = None) -> LowCmd:
    """LowCmd_ for `command` on a robot reporting `mode_machine` (echoed, as the robot requires).

    Joints the variant lacks, joints with enable False and the unused slots 29-34 are sent
    disabled with every field zero. Values are rounded to float32 as the wire carries them.
    """
    variant = variant_of(mode_machine)
    if mode_pr not in (0, 1):
        raise ValueError(f"mode_pr must be 0 (pitch/roll joints) or 1 (parallel motors A/B); got {mode_pr}")
    msg = out if out is not None else LowCmd()
    n = g1.NUM_JOINTS
    on = variant.active_mask & np.asarray(command.enable, dtype=bool)
    msg.mode_pr = mode_pr
    msg.mode_machine = int(mode_machine)
    msg.motor_mode[:] = MOTOR_DISABLED
    msg.motor_mode[:n] = on  # True -> 1 (MOTOR_ENABLED)
    for target, source in ((msg.motor_q_rad, command.q_rad), (msg.motor_dq_radps, command.dq_radps),
                           (msg.motor_tau_nm, command.tau_nm), (msg.motor_kp_nm_per_rad, command.kp),
                           (msg.motor_kd_nms_per_rad, command.kd)):
        target.fill(0.0)
        np.copyto(target[:n], source, casting="same_kind", where=on)
    return msg


def lowcmd_to_motor_command(msg: LowCmd) -> MotorCommand:
    """The command a robot executes for `msg`: disabled motors produce no torque at all."""
    n = g1.NUM_JOINTS
    enable = msg.motor_mode[:n] == MOTOR_ENABLED
    gate = enable.astype(np.float64)
    return MotorCommand(
        q_rad=msg.motor_q_rad[:n].astype(np.float64),
        dq_radps=msg.motor_dq_radps[:n].astype(np.float64),
        kp=msg.motor_kp_nm_per_rad[:n].astype(np.float64) * gate,
        kd=msg.motor_kd_nms_per_rad[:n].astype(np.float64) * gate,
        tau_nm=msg.motor_tau_nm[:n].astype(np.float64) * gate,
        enable=enable,
    )
