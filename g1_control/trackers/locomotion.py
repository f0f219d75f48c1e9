"""Velocity-command locomotion policy as a Tracker: styled walking, a planned pelvis height and
closed-loop velocity correction.

The reference's root velocity (heading frame) is the command. When the reference sets
`upper_body_override`, the plan drives the arms and the waist yaw (the waist roll/pitch lean to
balance the arms) while the policy, observing the upper body it was trained with, keeps balancing
(g1_control/trackers/styled.py). A reference
`pelvis_height_m` crouches the legs under the policy. The correction closes the loop on the
estimated base velocity, because the bare holosoma policies reach only ~80 % of the commanded
speed (docs/robot_facts.md).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from g1_control.interfaces import Tracker
from g1_control.robot import g1
from g1_control.rotations import projected_gravity
from g1_control.trackers.observation import ObservationBuilder
from g1_control.trackers.onnx_runner import OnnxRunner
from g1_control.trackers.policy_spec import PolicySpec
from g1_control.trackers.styled import LEGS, Crouch, PlannedUpperBody
from g1_control.types import CommandLimits, EstimatedState, JointReference, MotorCommand, RobotState


@dataclass
class VelocityCorrectionConfig:
    """Command shaping so that the achieved velocity follows the operator's command.

    policy_cmd = ff * cmd + ki * integral(cmd - v_est), on vx, vy and wz, clamped to the
    policy's command ranges. The feedforward comes from the policy's measured speed ratio; the
    integral removes what is left, on every axis while the robot walks: an axis commanded zero is
    held at zero (a styled pose that shifts the centre of mass drifted 0.26 m/s forward on a
    sideways command, measured). The integrals reset while the whole command is near zero (the
    policy then stands); each starts `settle_s` after the robot starts walking or its axis'
    command starts or stops.
    """

    enabled: bool = True
    feedforward: tuple[float, float, float] = (1.0, 1.5, 1.0)
    ki: tuple[float, float, float] = (2.0, 2.0, 1.0)
    integral_limit: tuple[float, float, float] = (0.5, 0.7, 0.4)
    velocity_filter_tau_s: float = 0.1
    settle_s: float = 1.0
    """The gait's first step goes the wrong way (-0.06 m/s sideways on a vy command); integrating
    it wound the integral up (vy 0.2 overshot by 17 %, measured), so each axis waits this long."""


class VelocityCorrector:
    def __init__(self, config: VelocityCorrectionConfig, dt_s: float):
        self.config = config
        self.dt_s = dt_s
        self._ff = tuple(float(v) for v in config.feedforward)
        self._ki = tuple(float(v) for v in config.ki)
        self._limit = tuple(float(v) for v in config.integral_limit)
        self._alpha = dt_s / (config.velocity_filter_tau_s + dt_s)
        self.integral = np.zeros(3)
        self.v_filtered = np.zeros(3)
        self.moving_s = np.zeros(3)
        """How long each axis has been corrected in its current state (commanded or held at zero)."""
        self._was_moving = [False, False, False]

    def reset(self) -> None:
        self.integral[:] = 0.0
        self.v_filtered[:] = 0.0
        self.moving_s[:] = 0.0
        self._was_moving[:] = [False, False, False]

    def __call__(self, cmd: np.ndarray, v_est: np.ndarray | None) -> np.ndarray:
        """cmd and v_est are (vx, vy, wz) in the heading frame."""
        if not self.config.enabled or v_est is None:
            return cmd
        # Per axis on Python floats (three values; numpy's per-call cost would dominate).
        alpha, dt, settle = self._alpha, self.dt_s, self.config.settle_s
        c, v = cmd.tolist(), v_est.tolist()
        vf = self.v_filtered.tolist()
        for i in range(3):
            vf[i] += alpha * (v[i] - vf[i])
        self.v_filtered[:] = vf
        moving = [abs(x) > 0.05 for x in c]
        if not any(moving):  # standing: the policy stands; nothing to correct
            self.integral[:] = 0.0
            self.moving_s[:] = 0.0
            self._was_moving[:] = [False, False, False]
            return cmd
        integral, moving_s = self.integral.tolist(), self.moving_s.tolist()
        out = [0.0, 0.0, 0.0]
        for i in range(3):
            if moving[i] != self._was_moving[i]:  # this axis' command started or stopped: start over
                integral[i] = moving_s[i] = 0.0
                self._was_moving[i] = moving[i]
            moving_s[i] += dt
            if moving_s[i] > settle:
                limit = self._limit[i]
                integral[i] = min(max(integral[i] + (c[i] - vf[i]) * dt * self._ki[i], -limit), limit)
            out[i] = self._ff[i] * c[i] + integral[i]
        self.integral[:] = integral
        self.moving_s[:] = moving_s
        return np.array(out)


class LocomotionPolicyTracker(Tracker):
    """Runs a velocity-command locomotion policy (e.g. holosoma's) at spec.rate_hz."""

    def __init__(self, spec: PolicySpec, correction: VelocityCorrectionConfig | None = None, *,
                 envelope_limits: bool = True):
        if spec.kind != "locomotion":
            raise ValueError(f"policy '{spec.name}' is a {spec.kind} policy, not a locomotion policy")
        self.spec = spec
        self.envelope_limits = envelope_limits
        self.dt_s = 1.0 / spec.rate_hz
        self.runner = OnnxRunner(spec.onnx_path, spec.input_name)
        self.obs = ObservationBuilder(spec.observation)
        self.corrector = VelocityCorrector(correction or VelocityCorrectionConfig(), self.dt_s)
        self.velocity_estimate: np.ndarray | None = None
        """(vx, vy, wz) in the heading frame, from the state estimator (observe())."""
        self.height_estimate: float | None = None
        """Pelvis height above the ground from the state estimator (observe())."""
        self.upper_body = PlannedUpperBody(spec.default_q_rad, self.dt_s)
        self.crouch = Crouch(spec.default_q_rad, self.dt_s)
        self._ranges = np.array([
            spec.command_ranges.get("lin_vel_x", (-1.0, 1.0)),
            spec.command_ranges.get("lin_vel_y", (-1.0, 1.0)),
            spec.command_ranges.get("ang_vel_yaw", (-1.0, 1.0)),
        ])
        self._lower = tuple(float(v) for v in self._ranges[:, 0])
        self._upper = tuple(float(v) for v in self._ranges[:, 1])
        self.last_action = np.zeros(g1.NUM_JOINTS)
        self.last_policy_command = np.zeros(3)
        self._phase = np.zeros(2)
        self._standing = True
        self._command = MotorCommand(q_rad=spec.default_q_rad.copy(), kp=spec.kp.copy(), kd=spec.kd.copy())
        # Observation inputs, reused every tick (the builder copies them into its own vector).
        self._cos_phase, self._sin_phase = np.zeros(2), np.zeros(2)
        self._dof_pos = np.zeros(g1.NUM_JOINTS)
        self._dof_vel = np.zeros(g1.NUM_JOINTS)
        self._values: dict[str, np.ndarray] = {"actions": self.last_action, "cos_phase": self._cos_phase,
                                               "sin_phase": self._sin_phase, "dof_pos": self._dof_pos}

    def observe(self, estimate: EstimatedState) -> None:
        self.velocity_estimate = estimate.heading_velocity
        self.height_estimate = estimate.pelvis_height_m

    @property
    def policy_command(self) -> np.ndarray:
        return self.last_policy_command

    @property
    def command_limits(self) -> CommandLimits:
        """What this tracker was measured to deliver (the spec's envelope, `g1 bench envelope`), or
        the policy's trained range when asked (envelope_limits False) or when none was measured."""
        if self.envelope_limits and self.spec.envelope is not None:
            return self.spec.envelope.command_limits
        return self.spec.command_limits

    def reset(self, state: RobotState | None = None) -> None:
        self.last_action[:] = 0.0
        self.corrector.reset()
        self.obs.reset()
        self.upper_body.reset()
        self.crouch.reset()
        self._command.dq_radps[:] = 0.0
        self._command.tau_nm[:] = 0.0
        self._standing = True
        if self.spec.phase is not None:
            self._phase = np.full(2, np.pi)

    def _advance_phase(self, cmd: np.ndarray) -> None:
        phase = self.spec.phase
        if phase is None:
            return
        step = 2 * np.pi * self.dt_s / phase.period_s
        p = self._phase
        p[:] = [math.fmod(a + step + np.pi, 2 * np.pi) - np.pi for a in p.tolist()]
        vx, vy, wz = cmd.tolist()
        if math.sqrt(vx * vx + vy * vy) < phase.stand_threshold and abs(wz) < phase.stand_threshold:
            p[:] = np.pi  # both feet in the same phase: stand
            self._standing = True
        elif self._standing:
            p[:] = phase.offsets_rad  # start the gait from its initial phase
            self._standing = False

    def act(self, reference: JointReference, state: RobotState) -> MotorCommand:
        lin, ang = reference.root_linvel_h_mps, reference.root_angvel_h_radps
        cmd = self.corrector(np.array((float(lin[0]), float(lin[1]), float(ang[2]))), self.velocity_estimate)
        cmd = np.array([min(max(c, lo), hi) for c, lo, hi in zip(cmd.tolist(), self._lower, self._upper)])
        self.last_policy_command = cmd
        self._advance_phase(cmd)
        styled = reference.upper_body_override
        crouch = self.crouch
        crouch.update(reference.pelvis_height_m, self.height_estimate)
        # What the policy observes: its joints, legs shifted back by the crouch, the upper body
        # as it was trained to see it when the plan drives it.
        v = self._values
        dof_pos = self._dof_pos
        np.subtract(state.q_rad, self.spec.default_q_rad, out=dof_pos)
        if crouch.angle_rad:
            dof_pos -= crouch.offset
        out = self._command
        if styled:
            self._dof_vel[:] = state.dq_radps
            v["dof_vel"] = self._dof_vel
            self.upper_body.begin(reference.q_rad)
            self.upper_body.observation(dof_pos, self._dof_vel)
        else:
            v["dof_vel"] = state.dq_radps
            if self.upper_body.active:  # handed back: clear what the override wrote
                self.upper_body.reset()
                out.dq_radps[:] = 0.0
                out.tau_nm[:] = 0.0
        v["base_ang_vel"] = state.imu_gyro_radps
        v["command_ang_vel"] = cmd[2:3]
        v["command_lin_vel"] = cmd[0:2]
        np.cos(self._phase, out=self._cos_phase)
        np.sin(self._phase, out=self._sin_phase)
        v["projected_gravity"] = projected_gravity(state.imu_quat_wxyz)
        action = self.runner(self.obs.build(v))
        clip = self.spec.action_clip
        np.minimum(np.maximum(action, -clip, out=action), clip, out=action)  # np.clip's result, cheaper
        np.copyto(self.last_action, action)
        np.multiply(self.last_action, self.spec.action_scale, out=out.q_rad)
        out.q_rad += self.spec.default_q_rad
        if crouch.angle_rad:
            out.q_rad[LEGS] += crouch.offset[LEGS]
        if styled:
            self.upper_body.command(out, state.imu_quat_wxyz, state.q_rad)
        return out
