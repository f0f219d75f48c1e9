"""Floating-base position from leg odometry: a stance foot does not move, so the base sits at the
foot's anchor minus the foot's offset from the base (forward kinematics with the IMU's
orientation). Between anchors the estimator's velocity (IMU + leg kinematics) carries the
position, and a first-order correction pulls it to the anchored value, so a change in the set of
stance feet never makes the position jump.

On steps (a height map of the scene, trackers/wbc/terrain.py), a foot's anchor takes its height
from the map at touchdown: the schedule's touchdown comes while the foot may still be above the
tread, and an anchor set there left the base (and the CoM's height reference) several centimetres
too high on the step, the stance knee straight (0.15 m step: 5 cm, measured).

Nothing here reads simulator ground truth: it is the same computation on the robot.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from g1_control.errors import WbcConfigError


class BaseOdometry:
    def __init__(self, correction_tau_s: float = 0.05):
        if correction_tau_s <= 0:
            raise WbcConfigError(f"odometry correction_tau_s must be > 0; got {correction_tau_s}")
        self.correction_tau_s = correction_tau_s
        self.base_pos_w_m = np.zeros(3)
        self.anchors_w_m = np.zeros((2, 3))
        self._anchored = np.zeros(2, dtype=bool)

    def reset(self, base_pos_w_m: np.ndarray, sole_offsets_w_m: np.ndarray) -> None:
        """Start at `base_pos_w_m` with both feet anchored where the kinematics put them."""
        self.base_pos_w_m = np.array(base_pos_w_m, dtype=float)
        self.anchors_w_m = self.base_pos_w_m + np.asarray(sole_offsets_w_m, dtype=float)
        self._anchored[:] = True

    def update(self, dt_s: float, base_linvel_w_mps: np.ndarray, sole_offsets_w_m: np.ndarray,
               stance: np.ndarray, ground_height: Callable[[np.ndarray], float] | None = None,
               stalled: bool = False) -> np.ndarray:
        """Advance by dt_s; sole_offsets_w_m: (2, 3) sole positions minus base position, world axes.
        ground_height: the map's height (m) at an xy (None: the anchor keeps the estimate's height).
        stalled: dt_s spans a stalled loop (several ticks): the velocity times dt_s is not where the
        base went, so the estimate is first corrected to the feet that stood before this tick, and a
        foot touching down now is anchored from the corrected estimate. (After a 120 ms stall the
        velocity left the base 1 cm low, a foot landing then was anchored there, and once the other foot
        lifted the base read 2 cm low: the swing foot's touchdown on a step came 2 cm above the tread,
        a fall; measured: sim2sim_step's timeline in lockstep, a stall at a touchdown.)"""
        p = self.base_pos_w_m
        p += base_linvel_w_mps * dt_s
        if stalled:
            standing = np.asarray(stance, dtype=bool) & self._anchored
            if standing.any():
                kin = (self.anchors_w_m[standing] - sole_offsets_w_m[standing]).mean(axis=0)
                p += dt_s / (self.correction_tau_s + dt_s) * (kin - p)
        kin, n = np.zeros(3), 0
        for i in range(2):
            if not stance[i]:
                self._anchored[i] = False
                continue
            if not self._anchored[i]:
                # Touchdown: anchor the foot where the current estimate puts it (continuity).
                self.anchors_w_m[i] = p + sole_offsets_w_m[i]
                if ground_height is not None:
                    self.anchors_w_m[i, 2] = ground_height(self.anchors_w_m[i, :2])
                self._anchored[i] = True
            kin += self.anchors_w_m[i] - sole_offsets_w_m[i]
            n += 1
        if n:
            gain = dt_s / (self.correction_tau_s + dt_s)
            p += gain * (kin / n - p)
        return p
