"""Prefer short steps: cost ||W dq||^2 (no target). Keeps the QP strictly convex and slows the
directions no other task constrains."""

from __future__ import annotations

import numpy as np

from g1_control.ik.configuration import Configuration
from g1_control.ik.tasks.base import Task, check_cost


class DampingTask(Task):
    """cost: scalar or (nv,) = (35,) per tangent direction (base 6 first, then joints)."""

    stackable = False

    def __init__(self, cost: float | np.ndarray = 1e-3, nv: int = 35) -> None:
        super().__init__(np.broadcast_to(check_cost("DampingTask", cost, nv), nv).copy(), gain=0.0)
        self._error = np.zeros(nv)
        self._jac = np.eye(nv)

    def compute_error(self, configuration: Configuration) -> np.ndarray:
        return self._error

    def compute_jacobian(self, configuration: Configuration) -> np.ndarray:
        return self._jac

    def add_objective(self, configuration: Configuration, hessian: np.ndarray, linear: np.ndarray) -> None:
        hessian.flat[:: hessian.shape[0] + 1] += self._w2
