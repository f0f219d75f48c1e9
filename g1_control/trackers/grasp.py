"""ForceLimitedGrasp: close a Dex3-1 hand until each finger feels the object, never squeezing
harder than a torque limit.

    grasp = ForceLimitedGrasp("right", torque_limit_nm=0.5)
    while not grasp.done:
        command = grasp.act(hands.read("right"), now_s)   # then GuardedHands.write("right", command)

Every closing joint's target moves toward the closed pose at `closing_speed_radps`, advancing
only when a new state arrived. A joint whose measured torque (the hand's tau_est, toward closing)
reaches touch_fraction * limit has touched: it stops closing, and its target is set once to the
angle where it touched + hold_fraction * limit / kp in the closing direction. As the finger then
presses in, kp (target - q) only falls, so the squeeze stays below hold_fraction * limit whatever
the object's stiffness; pushed back open (the object moved by the other fingers, or loaded), the
target follows the finger to keep that bound, so the finger gives way rather than squeeze harder. Touch is declared below the limit because the target keeps moving for the
loop's latency after the torque rose (measured on the emulator at 1.5 rad/s, 100 Hz: ~0.13 N m of
overshoot when joints were stopped only at the limit itself). A joint that reaches its closed
pose without touching anything stops too. thumb_0 (which swings the thumb across the palm rather
than closing it) holds its open angle.
"""

from __future__ import annotations

import numpy as np

from g1_control.robot import dex3
from g1_control.types import FingerCommand, FingerState

MAX_STEP_S = 0.02
"""The most closing time one new state advances the targets by, however long since the last one."""


KP_PER_NM = 6.0
"""Default position gain per N m of torque limit (kp 3 for 0.5 N m): the torque a target step adds
scales with the limit, so the overshoot past touch during the loop's latency is the same fraction
of any limit, and the hold offset (hold_fraction * limit / kp, 0.13 rad) is the same angle."""


SPEED_PER_NM = 3.0
MAX_CLOSING_SPEED_RADPS = 1.5
"""Default closing speed: 3 rad/s per N m of limit, at most 1.5 rad/s (0.9 rad/s for 0.3 N m). A
finger meets the object with its momentum: on the emulator (reflected inertia 1e-3 kg m^2, a stiff
object) 1.5 rad/s alone struck with ~0.2 N m, most of a 0.3 N m limit, before any torque reading
could stop it."""


class ForceLimitedGrasp:
    def __init__(self, side: dex3.Side, torque_limit_nm: float = 0.5, closing_speed_radps: float | None = None,
                 kp: float | None = None, kd: float = 0.05, hold_fraction: float = 0.8,
                 touch_fraction: float = 0.5):
        limits = dex3.hand_limits(side)
        if not 0 < torque_limit_nm <= float(np.min(limits.effort_nm)):
            raise ValueError(f"torque_limit_nm must be in (0, {float(np.min(limits.effort_nm)):g}] N m (the finger "
                             f"motors' effort limit in the URDF); got {torque_limit_nm}")
        if not 0 < hold_fraction <= 1 or not 0 < touch_fraction <= 1:
            raise ValueError(f"hold_fraction and touch_fraction must be in (0, 1]; got {hold_fraction}, "
                             f"{touch_fraction}")
        if kp is None:
            kp = KP_PER_NM * torque_limit_nm
        if closing_speed_radps is None:
            closing_speed_radps = min(MAX_CLOSING_SPEED_RADPS, SPEED_PER_NM * torque_limit_nm)
        if not closing_speed_radps > 0 or not kp > 0 or not kd >= 0:
            raise ValueError(f"closing_speed_radps and kp must be positive and kd >= 0; got "
                             f"{closing_speed_radps}, {kp}, {kd}")
        self.side, self.limits = side, limits
        self.torque_limit_nm, self.closing_speed_radps = torque_limit_nm, closing_speed_radps
        self.kp, self.kd, self.hold_fraction, self.touch_fraction = kp, kd, hold_fraction, touch_fraction
        self.sign = limits.closing_sign
        self.closing = self.sign != 0
        self.target: np.ndarray | None = None
        self.touched = np.zeros(dex3.NUM_MOTORS, dtype=bool)
        """Joints stopped by the torque limit (they touch the object)."""
        self.closed = np.zeros(dex3.NUM_MOTORS, dtype=bool)
        """Joints stopped at their closed pose without touching anything."""
        self._state_t: float | None = None

    @property
    def done(self) -> bool:
        """Every closing joint has stopped (on the object or at its closed pose)."""
        return bool(np.all((self.touched | self.closed)[self.closing]))

    def act(self, state: FingerState, now_s: float) -> FingerCommand:
        """The command for this tick from the hand's newest state (received at state.t_s)."""
        if self.target is None:
            self.target = np.where(self.closing, state.q_rad, self.limits.open_rad).astype(float)
        # Targets advance only on a state not seen before, by at most MAX_STEP_S of closing: a late
        # tick, or a hand whose samples stalled, must not wind the target up beyond what was felt.
        fresh = self._state_t is None or state.t_s != self._state_t
        dt = 0.0 if self._state_t is None or not fresh else min(max(0.0, state.t_s - self._state_t), MAX_STEP_S)
        self._state_t = state.t_s
        squeeze = self.sign * state.tau_nm  # the motors' torque toward closing: what the object resists
        touch = self.closing & ~self.touched & ~self.closed & (squeeze >= self.touch_fraction * self.torque_limit_nm)
        # held from the angle where it touched: as the finger presses in, the squeeze can only fall
        # below hold_fraction * limit (kp (target - q) with q moving toward the target)
        hold = state.q_rad + self.sign * self.hold_fraction * self.torque_limit_nm / self.kp
        self.target = np.where(touch, hold, self.target)
        self.touched |= touch
        # a touched finger that the object pushes back open (the other fingers pressing it across the
        # palm, a lift) gives way: its target follows it, so its squeeze stays at hold_fraction * limit
        # (held only from the touch angle, a thumb was pushed 0.11 rad open and squeezed 0.73 N m
        # against a 0.5 N m limit: a bottle in the simulated Dex3, launch/sim_bottle.yaml)
        pushed = self.touched & (self.sign * (self.target - hold) > 0)
        self.target = np.where(pushed, hold, self.target)
        moving = self.closing & ~self.touched & ~self.closed
        closed_pose = self.limits.closed_rad
        advanced = self.target + self.sign * self.closing_speed_radps * dt
        past = self.sign * (advanced - closed_pose) >= 0
        self.closed |= moving & past & (self.sign * (state.q_rad - closed_pose) >= -0.05)
        self.target = np.where(moving, np.where(past, closed_pose, advanced), self.target)
        return FingerCommand(q_rad=self.target.copy(), kp=np.full(dex3.NUM_MOTORS, self.kp),
                             kd=np.full(dex3.NUM_MOTORS, self.kd))
