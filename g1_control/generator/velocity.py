"""The simplest generator: the operator's velocity command as a whole-body reference.

Root velocity from the command, both feet in contact, and the posture of the commanded style
(g1_control/generator/styles.py: a waist and arm pose, maybe with a periodic part; legs at the
default pose). The 'default' style and the data-only styles leave the upper body to the tracker.
It is feasible by construction, so its retargeter only copies fields (no IK). The learned
generator replaces both without touching the loop.
"""

from __future__ import annotations

import numpy as np

from g1_control.generator.styles import ROLLOUT_STYLES
from g1_control.interfaces import Generator, Retargeter
from g1_control.robot import g1
from g1_control.types import Command, CommandLimits, JointReference, KinematicReference, RobotState


class VelocityReferenceGenerator(Generator):
    def __init__(self, limits: CommandLimits | None = None):
        self.limits = limits or CommandLimits()
        self._ref = KinematicReference(q_rad=g1.DEFAULT_Q_RAD.copy())

    def update(self, command: Command, state: RobotState) -> KinematicReference:
        v = self.limits.clamp_velocity(command.vx_mps, command.vy_mps, command.wz_radps)
        ref = self._ref
        ref.t_s = state.t_s
        ref.root_linvel_h_mps[:2] = v[:2]
        ref.root_angvel_h_radps[2] = v[2]
        ref.style = command.style
        style = ROLLOUT_STYLES.get(command.style)
        if style is not None and style.override:
            ref.q_rad[:] = style.pose(state.t_s)
            ref.upper_body_override = True
        else:
            ref.q_rad[:] = g1.DEFAULT_Q_RAD
            ref.upper_body_override = False
        return ref


class CopyRetargeter(Retargeter):
    """For references that are feasible by construction: copies fields, solves nothing."""

    def __init__(self) -> None:
        self._out = JointReference()

    def solve(self, reference: KinematicReference, q_prev: np.ndarray) -> JointReference:
        out = self._out
        out.t_s = reference.t_s
        out.q_rad[:] = reference.q_rad
        out.root_pos_w_m[:] = reference.root_pos_w_m
        out.root_quat_wxyz[:] = reference.root_quat_wxyz
        out.root_linvel_h_mps[:] = reference.root_linvel_h_mps
        out.root_angvel_h_radps[:] = reference.root_angvel_h_radps
        out.contacts[:] = reference.contacts
        out.upper_body_override = reference.upper_body_override
        return out
