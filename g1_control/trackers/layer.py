"""The tracking layer: the walking policy while the plan walks, the whole-body controller (WBC)
for whole-body phases, handed over by the reference's phase with a blended transition.

JointReference.phase says which controller the plan is meant for (types.PHASE_LOCOMOTION: the
walking policy follows the root velocity, with its styled upper body; PHASE_WHOLE_BODY: the WBC
follows root pose, joints, contact schedule and hand forces). The layer runs at the WBC's rate
(rates.tracker_hz, e.g. 100 Hz) and evaluates the 50 Hz policy every n-th tick, holding its
command in between, as its drivers would.

Hand-over: the incoming controller starts fresh (the WBC's odometry takes the reference's first
root position, which the generator builds from the measured pose; the policy's action history is
cleared), both run for `blend_s`, and the motor command is a torque-exact blend: with weights a
(outgoing) and b = 1 - a (incoming, a quintic ramp), per joint
    kp = a kpA + b kpB,  kd = a kdA + b kdB,
    q = (a kpA qA + b kpB qB) / kp,  dq = (a kdA dqA + b kdB dqB) / kd,  tau = a tauA + b tauB,
so the drivers' torque tau + kp (q - q_meas) + kd (dq - dq_meas) is exactly a tauA_out + b tauB_out.
Measured in the issue 17 investigation (standing, policy <-> WBC): largest per-tick torque jump
11.8 N m for a hard switch, 0.3-0.6 N m with a 0.3 s blend.

Walking with something held: a locomotion reference that carries a held object's forces on the hands
(JointReference.hand_forces_w_n, the goals' walk holding) goes to the WBC as well when the WBC has a gait
of its own (WbcConfig.footsteps "velocity"): it walks the reference's root twist with the load in its
dynamics and the held upper body, where the walking policy knows nothing of the load (the goals'
GoalConfig.walk_while_holding; launch/builder.py builds the layer's WBC so at rates.tracker_hz >= 250: at
100 Hz the gait carried worse than whole-body steps, measured on `g1 bench objects` scenes).
"""

from __future__ import annotations

import time

import numpy as np

from g1_control.interfaces import Tracker
from g1_control.trackers.locomotion import LocomotionPolicyTracker
from g1_control.trackers.wbc.tracker import WholeBodyTracker
from g1_control.types import (
    PHASE_WHOLE_BODY,
    CommandLimits,
    EstimatedState,
    JointReference,
    MotorCommand,
    RobotState,
)

POLICY, WBC = "policy", "wbc"
PROFILE_TICKS = 1 << 17
WBC_MIN_PELVIS_HEIGHT_M = 0.45
"""The lowest standing pelvis height the WBC path is measured to hold (issue 17)."""


def blend_commands(a: MotorCommand, b: MotorCommand, w_b: float, out: MotorCommand) -> MotorCommand:
    """Torque-exact blend of two motor commands (module docstring); w_b: the weight of b."""
    w_a = 1.0 - w_b
    kp = w_a * a.kp + w_b * b.kp
    kd = w_a * a.kd + w_b * b.kd
    safe_kp = np.where(kp > 1e-9, kp, 1.0)
    safe_kd = np.where(kd > 1e-9, kd, 1.0)
    out.q_rad[:] = np.where(kp > 1e-9, (w_a * a.kp * a.q_rad + w_b * b.kp * b.q_rad) / safe_kp, b.q_rad)
    out.dq_radps[:] = np.where(kd > 1e-9, (w_a * a.kd * a.dq_radps + w_b * b.kd * b.dq_radps) / safe_kd, b.dq_radps)
    out.kp[:] = kp
    out.kd[:] = kd
    out.tau_nm[:] = w_a * a.tau_nm + w_b * b.tau_nm
    return out


def _copy(src: MotorCommand, dst: MotorCommand) -> MotorCommand:
    dst.q_rad[:] = src.q_rad
    dst.dq_radps[:] = src.dq_radps
    dst.kp[:] = src.kp
    dst.kd[:] = src.kd
    dst.tau_nm[:] = src.tau_nm
    return dst


class TrackingLayer(Tracker):
    def __init__(self, policy: LocomotionPolicyTracker, wbc: WholeBodyTracker, rate_hz: float, blend_s: float = 0.3):
        self.policy, self.wbc = policy, wbc
        self.rate_hz = rate_hz
        self.every = max(1, round(rate_hz / policy.spec.rate_hz))
        self.blend_s = blend_s
        self._walks_holding = self.walks_holding()
        self._policy_cmd, self._wbc_cmd, self._out = MotorCommand(), MotorCommand(), MotorCommand()
        self._stand = JointReference()
        """What the policy is given while the plan is whole-body (during a blend out of it): stand."""
        self._last_wbc_ref = JointReference()
        self.switches: list[tuple[float, str]] = []
        self.cpu_s = np.zeros(PROFILE_TICKS)
        """Thread CPU time of each act() (the cost without other processes' preemption), ring buffer."""
        self.cpu_kind = np.zeros(PROFILE_TICKS, dtype=np.int8)
        """What ran in that act(): 0 the policy, 1 the WBC, 2 both (a hand-over blend)."""
        self.profiled = 0
        self.reset()

    # -- Tracker ------------------------------------------------------------------------------------
    def reset(self, state: RobotState | None = None) -> None:
        self.policy.reset(state)
        self.wbc.reset(state)
        self.active = POLICY
        self.previous: str | None = None
        self._switch_t = -np.inf
        self._tick = 0
        self._policy_due = True
        self._has_wbc_ref = False

    def observe(self, estimate: EstimatedState) -> None:
        self.policy.observe(estimate)

    @property
    def command_limits(self) -> CommandLimits:
        """The policy's velocity envelope; standing heights down to the WBC's."""
        lim = self.policy.command_limits
        return CommandLimits(lim.vx_mps, lim.vy_mps, lim.wz_radps,
                             (WBC_MIN_PELVIS_HEIGHT_M, max(lim.pelvis_height_m[1], WBC_MIN_PELVIS_HEIGHT_M)))

    @property
    def policy_command(self) -> np.ndarray | None:
        return self.policy.policy_command if self.active == POLICY or self.previous == POLICY else None

    def act(self, reference: JointReference, state: RobotState) -> MotorCommand:
        c0 = time.thread_time()
        out = self._act(reference, state)
        k = self.profiled % PROFILE_TICKS
        self.cpu_s[k] = time.thread_time() - c0
        self.cpu_kind[k] = 2 if self.previous is not None else (1 if self.active == WBC else 0)
        self.profiled += 1
        return out

    def cpu_samples(self) -> tuple[np.ndarray, np.ndarray]:
        """(seconds, kind) of the profiled act() calls (the last PROFILE_TICKS)."""
        n = min(self.profiled, PROFILE_TICKS)
        return self.cpu_s[:n].copy(), self.cpu_kind[:n].copy()

    def walks_holding(self) -> bool:
        """Whether a locomotion reference with a held load is walked by the WBC's own gait (module docstring)."""
        return getattr(self.wbc, "gait", None) is not None

    def _act(self, reference: JointReference, state: RobotState) -> MotorCommand:
        holding = self._walks_holding and reference.holding
        want = WBC if reference.phase == PHASE_WHOLE_BODY or holding else POLICY
        if want != self.active:
            self._switch(want, state)
        if want == WBC:
            self._last_wbc_ref.copy_from(reference)
            self._has_wbc_ref = True
        blending = self.previous is not None
        w = 1.0 if self.blend_s <= 0 else min(1.0, (state.t_s - self._switch_t) / self.blend_s)
        if w >= 1.0:
            self.previous, blending = None, False
        need_policy = self.active == POLICY or (blending and self.previous == POLICY)
        need_wbc = self.active == WBC or (blending and self.previous == WBC)
        if need_policy and (self._policy_due or self._tick % self.every == 0):
            self._policy_due = False
            _copy(self.policy.act(reference if want == POLICY else self._stand, state), self._policy_cmd)
        if need_wbc:
            _copy(self.wbc.act(self._last_wbc_ref, state), self._wbc_cmd)
        self._tick += 1
        commands = {POLICY: self._policy_cmd, WBC: self._wbc_cmd}
        if not blending:
            return _copy(commands[self.active], self._out)
        assert self.previous is not None
        s = w**3 * (10 - 15 * w + 6 * w * w)
        return blend_commands(commands[self.previous], commands[self.active], s, self._out)

    def _switch(self, target: str, state: RobotState) -> None:
        if target == WBC:
            self.wbc.reset(state)
        else:
            self.policy.reset(state)
            self._policy_due = True
        self.previous, self.active = self.active, target
        self._switch_t = state.t_s
        self.switches.append((state.t_s, target))


__all__ = ["POLICY", "WBC", "TrackingLayer", "blend_commands"]
