"""Keep the 29 joints inside their position limits (g1.Q_MIN_RAD / Q_MAX_RAD) after the step.

Joint coordinates are linear in dq, so the bound is exact: the step lands inside the limits
whatever its size (no gain is needed as in velocity-space formulations).
"""

from __future__ import annotations

import numpy as np

from g1_control.ik.configuration import Configuration
from g1_control.ik.exceptions import LimitDefinitionError
from g1_control.ik.limits.base import INF, BoxBounds, Limit
from g1_control.robot import g1


class JointPositionLimit(Limit):
    def __init__(self, q_min_rad: np.ndarray = g1.Q_MIN_RAD, q_max_rad: np.ndarray = g1.Q_MAX_RAD,
                 margin_rad: float = 0.0) -> None:
        q_min, q_max = np.asarray(q_min_rad, dtype=float), np.asarray(q_max_rad, dtype=float)
        if q_min.shape != (g1.NUM_JOINTS,) or q_max.shape != (g1.NUM_JOINTS,):
            raise LimitDefinitionError(f"JointPositionLimit bounds must have shape ({g1.NUM_JOINTS},). "
                                       f"Got {q_min.shape} and {q_max.shape}")
        if margin_rad < 0 or np.any(q_max - q_min <= 2 * margin_rad):
            raise LimitDefinitionError(f"JointPositionLimit needs q_max - q_min > 2 * margin ({margin_rad} rad) "
                                       "for every joint")
        self.q_min_rad = q_min + margin_rad
        self.q_max_rad = q_max - margin_rad
        self._box: BoxBounds | None = None

    def compute(self, configuration: Configuration, dt_s: float) -> BoxBounds:
        nv = configuration.nv
        if self._box is None or self._box.lower.shape[0] != nv:
            self._box = BoxBounds(np.full(nv, -INF), np.full(nv, INF))
        k = nv - g1.NUM_JOINTS
        q = configuration.joint_q_rad
        np.subtract(self.q_min_rad, q, out=self._box.lower[k:])
        np.subtract(self.q_max_rad, q, out=self._box.upper[k:])
        return self._box
