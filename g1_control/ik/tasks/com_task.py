"""Put the whole-body centre of mass at a world point. Error c - c* (m, world)."""

from __future__ import annotations

import numpy as np

from g1_control.ik.configuration import Configuration
from g1_control.ik.exceptions import TaskDefinitionError
from g1_control.ik.tasks.base import Task, check_cost


class ComTask(Task):
    """cost: scalar or (3,) per world axis (e.g. (1, 1, 0) to place the CoM over the feet only)."""

    def __init__(self, cost: float | np.ndarray = 1.0, gain: float = 1.0, lm_damping: float = 0.0) -> None:
        super().__init__(np.broadcast_to(check_cost("ComTask", cost, 3), 3).copy(), gain, lm_damping)
        self.target_w_m: np.ndarray | None = None
        self._error = np.zeros(3)

    def set_target(self, com_w_m: np.ndarray, check: bool = True) -> None:
        target = np.asarray(com_w_m, dtype=float)
        if check and (target.shape != (3,) or not np.isfinite(target).all()):
            raise TaskDefinitionError(f"ComTask target must be 3 finite numbers (m). Got {com_w_m!r}")
        self.target_w_m = target.copy()

    def set_target_from_configuration(self, configuration: Configuration) -> None:
        self.target_w_m = configuration.com_w_m.copy()

    def compute_error(self, configuration: Configuration) -> np.ndarray:
        if self.target_w_m is None:
            raise TaskDefinitionError("ComTask has no target; call set_target first")
        np.subtract(configuration.com_w_m, self.target_w_m, out=self._error)
        return self._error

    def compute_jacobian(self, configuration: Configuration) -> np.ndarray:
        return configuration.com_jacobian
