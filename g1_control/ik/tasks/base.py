"""What every IK task shares: an error e(q), its Jacobian J = de/d(dq), and the QP cost it adds.

A task asks the step dq to cancel a fraction `gain` of its error:
    minimize  1/2 || W (J dq + gain * e) ||^2  (+ 1/2 lm_damping ||W e||^2 ||dq||^2)
W is the diagonal of `cost` (units: 1 / error unit); gain 1 means "reach the target in one step
if nothing else objects"; the Levenberg-Marquardt term keeps steps short far from the target,
where the linearisation is poor.
"""

from __future__ import annotations

import abc

import numpy as np

from g1_control.ik.configuration import Configuration
from g1_control.ik.exceptions import TaskDefinitionError


def check_cost(owner: str, cost: np.ndarray | float, size: int, allowed: tuple[int, ...] = ()) -> np.ndarray:
    """Validate a cost given as a scalar or a vector of `size` (or one of `allowed` sizes)."""
    arr = np.atleast_1d(np.asarray(cost, dtype=float))
    sizes = (1, size) + allowed
    if arr.ndim != 1 or arr.shape[0] not in sizes:
        raise TaskDefinitionError(
            f"{owner} cost must be a scalar or a vector of shape {' or '.join(f'({s},)' for s in sizes)}. "
            f"Got {arr.shape}"
        )
    if not np.all(np.isfinite(arr)) or np.any(arr < 0):
        raise TaskDefinitionError(f"{owner} cost must be finite and >= 0. Got {arr}")
    return arr


class Task(abc.ABC):
    """Base class: subclasses define `compute_error` and `compute_jacobian`."""

    stackable = True
    """True when the cost is exactly the base formula, so a solver may stack this task's rows with
    others' and form J^T W^2 J once (tasks that override add_objective set it False)."""

    def __init__(self, cost: np.ndarray, gain: float = 1.0, lm_damping: float = 0.0) -> None:
        if not 0.0 <= gain <= 1.0:
            raise TaskDefinitionError(f"{type(self).__name__} gain must be in [0, 1]. Got {gain}")
        if lm_damping < 0:
            raise TaskDefinitionError(f"{type(self).__name__} lm_damping must be >= 0. Got {lm_damping}")
        self.cost = cost
        self.gain = float(gain)
        self.lm_damping = float(lm_damping)

    @property
    def cost(self) -> np.ndarray:
        return self._cost

    @cost.setter
    def cost(self, value: np.ndarray) -> None:
        self._cost = np.asarray(value, dtype=float)
        self._w2 = self._cost**2  # squared once here, not every tick

    @abc.abstractmethod
    def compute_error(self, configuration: Configuration) -> np.ndarray:
        """Error vector e(q); zero when the task is met."""

    @abc.abstractmethod
    def compute_jacobian(self, configuration: Configuration) -> np.ndarray:
        """(len(e), nv) matrix J with e(q + dq) ~ e(q) + J dq."""

    def compute_error_and_jacobian(self, configuration: Configuration) -> tuple[np.ndarray, np.ndarray]:
        """Both at once; tasks override it when sharing the work is cheaper (the per-tick path)."""
        return self.compute_error(configuration), self.compute_jacobian(configuration)

    def add_objective(self, configuration: Configuration, hessian: np.ndarray, linear: np.ndarray) -> None:
        """Add this task's quadratic cost to (H, c) in place."""
        error, jac = self.compute_error_and_jacobian(configuration)
        w2 = self._w2 if self._w2.shape == error.shape else np.broadcast_to(self._w2, error.shape)
        jw = jac.T * w2
        hessian += jw @ jac
        linear += self.gain * (jw @ error)
        if self.lm_damping > 0.0:
            mu = self.lm_damping * float(w2 @ (error * error))
            hessian.flat[:: hessian.shape[0] + 1] += mu

    def compute_qp_objective(self, configuration: Configuration) -> tuple[np.ndarray, np.ndarray]:
        """(H, c) of this task alone."""
        nv = configuration.nv
        hessian, linear = np.zeros((nv, nv)), np.zeros(nv)
        self.add_objective(configuration, hessian, linear)
        return hessian, linear
