"""Acceleration tasks for the inverse-dynamics QP.

Each task asks for J ddq + J_dot v = a_des, where a_des is a PD law on the task error plus the
reference's feedforward acceleration. The QP minimises sum_k ||W_k (J_k ddq - (a_des_k - drift_k))||^2,
so a task contributes J^T W J to the Hessian and -J^T W (a_des - drift) to the gradient.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from g1_control.errors import WbcConfigError
from g1_control.rotations import rotation_error


@dataclass(frozen=True)
class TaskGains:
    """PD gains of an acceleration task (1/s^2, 1/s) and its weight in the QP cost."""

    kp: float
    kd: float
    weight: float

    def __post_init__(self) -> None:
        if self.kp < 0 or self.kd < 0 or self.weight < 0 or not np.isfinite(self.kp + self.kd + self.weight):
            raise WbcConfigError(f"TaskGains need finite kp, kd, weight >= 0; got {self.kp}, {self.kd}, {self.weight}")

    @classmethod
    def critically_damped(cls, frequency_hz: float, weight: float) -> TaskGains:
        wn = 2 * np.pi * frequency_hz
        return cls(wn * wn, 2.0 * wn, weight)


@dataclass
class AccelerationTask:
    """One weighted least-squares term: want jac @ ddq == target (target = a_des - drift)."""

    name: str
    jac: np.ndarray
    target: np.ndarray
    weight: np.ndarray
    """Per-row weight (the square root enters the residual, so this is W^T W)."""
    joint_space: bool = False
    """jac is the identity on the last len(target) velocity coordinates (posture_task): the QP adds
    the weights to its Hessian's diagonal instead of multiplying the Jacobian out."""




def position_task(name: str, jac: np.ndarray, drift: np.ndarray, pos: np.ndarray, vel: np.ndarray,
                  pos_ref: np.ndarray, vel_ref: np.ndarray, acc_ref: np.ndarray, gains: TaskGains,
                  axes: np.ndarray | None = None) -> AccelerationTask:
    """Point task (3 rows). `axes` (3 weights in 0..1) masks axes, e.g. to leave z to another task."""
    a_des = acc_ref + gains.kp * (pos_ref - pos) + gains.kd * (vel_ref - vel)
    weight = np.full(3, gains.weight) if axes is None else gains.weight * np.asarray(axes, dtype=float)
    return AccelerationTask(name, jac, a_des - drift, weight)


def orientation_task(name: str, jac_ang: np.ndarray, drift_ang: np.ndarray, rot: np.ndarray,
                     angvel: np.ndarray, rot_ref: np.ndarray, angvel_ref: np.ndarray,
                     gains: TaskGains) -> AccelerationTask:
    """Orientation task (3 rows, world axes)."""
    a_des = gains.kp * rotation_error(rot_ref, rot) + gains.kd * (angvel_ref - angvel)
    return AccelerationTask(name, jac_ang, a_des - drift_ang, np.full(3, gains.weight))


def posture_task(nv: int, q: np.ndarray, dq: np.ndarray, q_ref: np.ndarray, dq_ref: np.ndarray,
                 gains: TaskGains, joint_weights: np.ndarray | None = None) -> AccelerationTask:
    """Joint-space task on the actuated joints (the last len(q) velocity coordinates)."""
    a_des = gains.kp * (q_ref - q) + gains.kd * (dq_ref - dq)
    n = len(q)
    weight = np.full(n, gains.weight) if joint_weights is None else gains.weight * joint_weights
    return AccelerationTask("posture", _joint_space_jacobian(n, nv), a_des, weight, joint_space=True)


@functools.cache
def _joint_space_jacobian(n: int, nv: int) -> np.ndarray:
    """(n, nv): the identity on the last n velocity coordinates (read-only: one array serves every tick)."""
    jac = np.zeros((n, nv))
    jac[:, nv - n:] = np.eye(n)
    jac.flags.writeable = False
    return jac
