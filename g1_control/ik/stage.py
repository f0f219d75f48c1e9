"""`IKStage`: the loop's one IK stage, between the generator and the tracker.

A reference that carries a plan feasible by construction (KinematicReference.feasible_plan: a
sampled whole-body plan, the velocity generator's pose) goes to the tracker as it is, the very
object the generator filled. Any other reference is solved by the differential-IK QP
(retargeter.py: IKRetargeter, configured by the launch file's `ik:` section through
g1_control/launch/builder.py:make_ik); what the IK does not solve passes through with it: the root
twist (IKRetargeter), the upper-body override, the pelvis height and the phase.
"""

from __future__ import annotations

import numpy as np

from g1_control.ik.retargeter import IKConfig, IKRetargeter
from g1_control.interfaces import Retargeter
from g1_control.types import JointReference, KinematicReference


class IKStage(Retargeter):
    """Retargeter (interfaces.Retargeter): pass a feasible plan through, else solve with `ik`."""

    def __init__(self, ik: IKRetargeter | IKConfig | None = None):
        self.ik = ik if isinstance(ik, IKRetargeter) else IKRetargeter(ik)
        self.solved_ticks = 0
        """References solved by the IK since creation (the rest were passed through)."""

    def solve(self, reference: KinematicReference, q_prev: np.ndarray) -> JointReference:
        plan = reference.feasible_plan
        if plan is not None:
            return plan
        out = self.ik.solve(reference, q_prev)
        out.pelvis_height_m = reference.pelvis_height_m
        out.phase = reference.phase
        self.solved_ticks += 1
        return out

    def describe(self) -> str:
        """One line for the loop's chain: the solver and what the launch file set."""
        c = self.ik.config
        return (f"{type(self).__name__} [feasible plans pass; else {c.backend} QP, {c.iterations} iteration(s) "
                f"at {1.0 / c.dt_s:g} Hz, contacts {'held' if c.hold_contacts else 'free'}]")


__all__ = ["IKStage"]
