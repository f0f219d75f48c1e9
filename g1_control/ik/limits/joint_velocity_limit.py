"""Keep joint speeds within the motor limits (g1.VELOCITY_LIMIT_RADPS) over each tick.

The bound is taken from an anchor, the joint angles at the start of the tick, not from the
current iterate: several IK iterations inside one tick then still move each joint at most
v_max * dt in total (applying the bound per iteration would let k iterations move k times as far,
the way velocity limits end up silently not applied).
"""

from __future__ import annotations

import numpy as np

from g1_control.ik.configuration import Configuration
from g1_control.ik.exceptions import LimitDefinitionError
from g1_control.ik.limits.base import INF, BoxBounds, Limit
from g1_control.robot import g1


class JointVelocityLimit(Limit):
    def __init__(self, velocity_limit_radps: np.ndarray | float = g1.VELOCITY_LIMIT_RADPS, scale: float = 1.0) -> None:
        v = np.broadcast_to(np.asarray(velocity_limit_radps, dtype=float), (g1.NUM_JOINTS,)).copy()
        if not np.all(np.isfinite(v)) or np.any(v <= 0) or not 0 < scale <= 1:
            raise LimitDefinitionError("JointVelocityLimit needs positive finite limits (rad/s) and scale in (0, 1]. "
                                       f"Got limits {v} and scale {scale}")
        self.velocity_limit_radps = v * scale
        self.anchor_q_rad: np.ndarray | None = None
        self._box: BoxBounds | None = None

    def set_anchor(self, joint_q_rad: np.ndarray) -> None:
        """Joint angles at the start of the tick; the tick's motion is bounded around them."""
        self.anchor_q_rad = np.asarray(joint_q_rad, dtype=float).copy()

    def compute(self, configuration: Configuration, dt_s: float) -> BoxBounds:
        if dt_s <= 0:
            raise LimitDefinitionError(f"JointVelocityLimit needs dt_s > 0. Got {dt_s}")
        nv = configuration.nv
        if self._box is None or self._box.lower.shape[0] != nv:
            self._box = BoxBounds(np.full(nv, -INF), np.full(nv, INF))
        k = nv - g1.NUM_JOINTS
        reach = self.velocity_limit_radps * dt_s
        q = configuration.joint_q_rad
        anchor = q if self.anchor_q_rad is None else self.anchor_q_rad
        self._box.lower[k:] = anchor - reach - q
        self._box.upper[k:] = anchor + reach - q
        return self._box
