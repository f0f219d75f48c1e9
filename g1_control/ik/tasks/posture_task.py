"""Pull the 29 joints toward a posture (regularises the redundant directions). Error q - q* (rad)."""

from __future__ import annotations

import numpy as np

from g1_control.ik.configuration import Configuration
from g1_control.ik.exceptions import TaskDefinitionError
from g1_control.ik.tasks.base import Task, check_cost
from g1_control.robot import g1


class PostureTask(Task):
    """cost: scalar or (29,) per joint (1/rad)."""

    stackable = False

    def __init__(self, cost: float | np.ndarray = 1e-2, gain: float = 1.0, lm_damping: float = 0.0) -> None:
        super().__init__(np.broadcast_to(check_cost("PostureTask", cost, g1.NUM_JOINTS), g1.NUM_JOINTS).copy(),
                         gain, lm_damping)
        self.target_q_rad: np.ndarray | None = None
        self._error = np.zeros(g1.NUM_JOINTS)
        self._jac: np.ndarray | None = None

    def set_target(self, q_rad: np.ndarray, check: bool = True) -> None:
        """check=False skips validation (for callers that validated the whole reference already)."""
        if not check:
            self.target_q_rad = q_rad
            return
        target = np.asarray(q_rad, dtype=float)
        if target.shape != (g1.NUM_JOINTS,) or not np.all(np.isfinite(target)):
            raise TaskDefinitionError(
                f"PostureTask target must be {g1.NUM_JOINTS} finite joint angles (rad). Got shape {target.shape}")
        self.target_q_rad = target.copy()

    def compute_error(self, configuration: Configuration) -> np.ndarray:
        if self.target_q_rad is None:
            raise TaskDefinitionError("PostureTask has no target; call set_target first")
        np.subtract(configuration.joint_q_rad, self.target_q_rad, out=self._error)
        return self._error

    def compute_jacobian(self, configuration: Configuration) -> np.ndarray:
        if self._jac is None or self._jac.shape[1] != configuration.nv:
            self._jac = np.zeros((g1.NUM_JOINTS, configuration.nv))
            self._jac[:, configuration.nv - g1.NUM_JOINTS:] = np.eye(g1.NUM_JOINTS)
        return self._jac

    def add_objective(self, configuration: Configuration, hessian: np.ndarray, linear: np.ndarray) -> None:
        # J is a selection matrix: add the diagonal directly instead of forming J^T W^2 J.
        error = self.compute_error(configuration)
        w2 = self.cost**2
        k = configuration.nv - g1.NUM_JOINTS
        hessian.flat[k * (configuration.nv + 1):: configuration.nv + 1] += w2
        linear[k:] += self.gain * w2 * error
        if self.lm_damping > 0.0:
            hessian.flat[:: hessian.shape[0] + 1] += self.lm_damping * float(w2 @ (error * error))
