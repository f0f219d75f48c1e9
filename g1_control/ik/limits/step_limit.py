"""Bound each coordinate of the step: |dq_i| <= bound_i. A trust region: the retargeter shortens a
step whose linearised collision rows let a pair end deep inside (a wrist swinging 1 rad in one
tick moves its witness points far from where the rows were taken)."""

from __future__ import annotations

import numpy as np

from g1_control.ik.configuration import Configuration
from g1_control.ik.limits.base import BoxBounds, Limit


class StepLimit(Limit):
    def __init__(self, bound: np.ndarray) -> None:
        self.bound = np.abs(np.asarray(bound, dtype=float))

    def compute(self, configuration: Configuration, dt_s: float) -> BoxBounds:
        return BoxBounds(-self.bound, self.bound.copy())
