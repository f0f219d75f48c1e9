"""The generator's path to a locomotion tracker: the IK retargeter makes the whole-body
reference feasible (limits, held stance feet, ground, effector/frame targets), then the plan's
heading-frame root velocity (passed through the IK) is the tracker's command and the upper body is overridden, so
the policy walks the generated root path while waist and arms follow the generated pose."""

from __future__ import annotations

import numpy as np

from g1_control.interfaces import Retargeter
from g1_control.types import JointReference, KinematicReference


class GeneratorRetargeter(Retargeter):
    def __init__(self, ik: Retargeter | None = None, upper_body_override: bool = True):
        if ik is None:
            from g1_control.ik.retargeter import IKConfig, IKRetargeter

            # The legs belong to the policy: holding stance feet where they touched down or
            # moving the CoM would make the IK bend the arms to reach a generated root the real
            # robot is not at (measured: it swung both arms overhead and tipped the robot over).
            # What the IK adds here is feasibility of the upper body: joint position and velocity
            # limits, smoothness, and effector goals as frame targets.
            ik = IKRetargeter(IKConfig(hold_contacts=False, com_cost=(0.0, 0.0, 0.0)))
        self.ik = ik
        self.upper_body_override = upper_body_override

    def solve(self, reference: KinematicReference, q_prev: np.ndarray) -> JointReference:
        out = self.ik.solve(reference, q_prev)
        out.upper_body_override = self.upper_body_override
        out.pelvis_height_m = reference.pelvis_height_m
        return out
