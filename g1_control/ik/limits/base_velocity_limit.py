"""Bound the floating base's linear (m/s) and angular (rad/s) speed over each tick.

Mocap noise or a target jump would otherwise teleport the pelvis, which no tracker can follow.
Like the joint velocity limit it is anchored at the tick's start pose; the bound is on the
base-frame displacement log6(T_anchor^-1 T), to first order.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from g1_control.ik.configuration import Configuration
from g1_control.ik.exceptions import LimitDefinitionError
from g1_control.ik.limits.base import INF, BoxBounds, Limit


def _base_placement(q: np.ndarray) -> pin.SE3:
    """Base pose from a pinocchio configuration (x y z, qx qy qz qw; the quaternion normalised)."""
    pose = q[:7].copy()
    pose[3:] /= np.linalg.norm(pose[3:])
    return pin.XYZQUATToSE3(pose)


class BaseVelocityLimit(Limit):
    def __init__(self, max_linear_mps: float = 3.0, max_angular_radps: float = 6.0) -> None:
        if not (max_linear_mps > 0 and max_angular_radps > 0):
            raise LimitDefinitionError("BaseVelocityLimit needs positive limits. "
                                       f"Got {max_linear_mps} m/s and {max_angular_radps} rad/s")
        self.max_linear_mps = float(max_linear_mps)
        self.max_angular_radps = float(max_angular_radps)
        self._reach = np.array([self.max_linear_mps] * 3 + [self.max_angular_radps] * 3)
        self.anchor: pin.SE3 | None = None
        self._box: BoxBounds | None = None

    def set_anchor(self, q: np.ndarray) -> None:
        """Pinocchio configuration at the start of the tick."""
        self.anchor = _base_placement(np.asarray(q, dtype=float))

    def compute(self, configuration: Configuration, dt_s: float) -> BoxBounds:
        nv = configuration.nv
        if self._box is None or self._box.lower.shape[0] != nv:
            self._box = BoxBounds(np.full(nv, -INF), np.full(nv, INF))
        reach = self._reach * dt_s
        if self.anchor is not None:
            # joint 1 is the free flyer: its placement is the base pose, already computed
            done = pin.log6(self.anchor.actInv(configuration.data.oMi[1])).vector
            np.subtract(-reach, done, out=self._box.lower[:6])
            np.subtract(reach, done, out=self._box.upper[:6])
        else:
            self._box.lower[:6] = -reach
            self._box.upper[:6] = reach
        return self._box
