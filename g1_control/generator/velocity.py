"""The simplest generator: the operator's velocity command as a whole-body reference.

Root velocity from the command, both feet in contact, and the posture of the commanded style
(g1_control/generator/styles.py: a waist and arm pose, maybe with a periodic part; legs at the
default pose). The 'default' style and the data-only styles leave the upper body to the tracker.
It is feasible by construction: each reference carries its own joint reference as the feasible
plan, which the IK stage passes on without solving. The learned generator replaces it without
touching the loop.
"""

from __future__ import annotations

import numpy as np

from g1_control.generator.styles import ROLLOUT_STYLES
from g1_control.interfaces import Generator
from g1_control.robot import g1
from g1_control.types import Command, CommandLimits, JointReference, KinematicReference, RobotState


class VelocityReferenceGenerator(Generator):
    """A style change blends the posture over `blend_s` (from the measured arms when the tracker
    had them, else from the previous pose); handing the upper body back to the tracker ('default')
    keeps the override until the blend has brought the arms to the default pose."""

    def __init__(self, limits: CommandLimits | None = None, blend_s: float = 0.5):
        self.limits = limits or CommandLimits()
        self.blend_s = blend_s
        self._ref = KinematicReference(q_rad=g1.DEFAULT_Q_RAD.copy())
        self._plan = JointReference()
        self._ref.feasible_plan = self._plan
        self._style: str | None = None
        self._from_q = g1.DEFAULT_Q_RAD.copy()
        self._from_override = False
        self._switch_t = -np.inf

    def reset(self, state: RobotState) -> None:
        self._style = None
        self._switch_t = -np.inf
        self._ref.upper_body_override = False

    def update(self, command: Command, state: RobotState) -> KinematicReference:
        v = self.limits.clamp_velocity(command.vx_mps, command.vy_mps, command.wz_radps)
        ref = self._ref
        t = state.t_s
        ref.t_s = t
        ref.root_linvel_h_mps[:2] = v[:2]
        ref.root_angvel_h_radps[2] = v[2]
        ref.pelvis_height_m = command.pelvis_height_m
        ref.style = command.style
        style = ROLLOUT_STYLES.get(command.style)
        if style is not None and not style.override:
            style = None  # the tracker's own upper body
        if command.style != self._style:
            if self._style is not None:
                self._switch_t = t
                self._from_q[:] = ref.q_rad if ref.upper_body_override else state.q_rad
                self._from_override = ref.upper_body_override
            self._style = command.style
        override = style is not None
        target = style.pose(t) if style is not None else g1.DEFAULT_Q_RAD
        w = (t - self._switch_t) / self.blend_s if self.blend_s > 0 else 1.0
        if w < 1.0:
            ref.q_rad[:] = self._from_q
            ref.q_rad += w * (target - self._from_q)
            ref.q_rad[: len(g1.LEG_JOINTS)] = g1.DEFAULT_Q_RAD[: len(g1.LEG_JOINTS)]
            ref.upper_body_override = override or self._from_override
        else:
            ref.q_rad[:] = target
            ref.upper_body_override = override
        self._fill_plan(ref)
        return ref

    def _fill_plan(self, reference: KinematicReference) -> None:
        """The reference as the tracker takes it (no joint velocities, no hand forces)."""
        out = self._plan
        out.t_s = reference.t_s
        out.q_rad[:] = reference.q_rad
        out.root_pos_w_m[:] = reference.root_pos_w_m
        out.root_quat_wxyz[:] = reference.root_quat_wxyz
        out.root_linvel_h_mps[:] = reference.root_linvel_h_mps
        out.root_angvel_h_radps[:] = reference.root_angvel_h_radps
        out.contacts[:] = reference.contacts
        out.upper_body_override = reference.upper_body_override
        out.pelvis_height_m = reference.pelvis_height_m
