"""The motor law the G1's joint drivers run, shared by the simulator and the robot emulator.

    tau = tau_ff + kp * (q* - q) + kd * (dq* - dq), clipped to the joint's effort limit.

A disabled motor (enable False) produces no torque, as on the robot.
"""

from __future__ import annotations

import numpy as np

from g1_control.robot.g1 import EFFORT_LIMIT_NM
from g1_control.types import MotorCommand


def motor_torque(command: MotorCommand, q_rad: np.ndarray, dq_radps: np.ndarray,
                 out: np.ndarray | None = None) -> np.ndarray:
    """Joint torques (N m) the drivers apply for `command` at the measured state."""
    tau = np.multiply(command.kp, command.q_rad - q_rad, out=out)
    tau += command.kd * (command.dq_radps - dq_radps)
    tau += command.tau_nm
    np.minimum(tau, EFFORT_LIMIT_NM, out=tau)
    np.maximum(tau, -EFFORT_LIMIT_NM, out=tau)
    if not command.enable.all():
        tau[~command.enable] = 0.0
    return tau
