"""Temporal smoothness: prefer this tick's step to repeat the previous one, cost ||W (dq - dq_prev)||^2.

Frame-by-frame IK without it jitters (each frame's optimum jumps between near-equal solutions);
penalising the change of velocity (a discrete acceleration) removes that without lag on smooth
motion. The caller sets the previous step with `set_previous_step` once per tick.
"""

from __future__ import annotations

import numpy as np

from g1_control.ik.configuration import Configuration
from g1_control.ik.exceptions import TaskDefinitionError
from g1_control.ik.tasks.base import Task, check_cost


class SmoothnessTask(Task):
    """cost: scalar or (nv,) per tangent direction."""

    stackable = False

    def __init__(self, cost: float | np.ndarray = 1e-1, nv: int = 35) -> None:
        super().__init__(np.broadcast_to(check_cost("SmoothnessTask", cost, nv), nv).copy(), gain=1.0)
        self.previous_step = np.zeros(nv)
        self._jac = np.eye(nv)

    def set_previous_step(self, dq: np.ndarray, check: bool = True) -> None:
        dq = np.asarray(dq, dtype=float)
        if check and (dq.shape != self.previous_step.shape or not np.isfinite(dq).all()):
            raise TaskDefinitionError(
                f"SmoothnessTask previous step must be {self.previous_step.shape[0]} finite numbers. Got {dq.shape}")
        self.previous_step[:] = dq

    def compute_error(self, configuration: Configuration) -> np.ndarray:
        return -self.previous_step

    def compute_jacobian(self, configuration: Configuration) -> np.ndarray:
        return self._jac

    def add_objective(self, configuration: Configuration, hessian: np.ndarray, linear: np.ndarray) -> None:
        w2 = self._w2
        hessian.flat[:: hessian.shape[0] + 1] += w2
        linear -= w2 * self.previous_step
