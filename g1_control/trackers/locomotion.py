"""Velocity-command locomotion policy as a Tracker, with an upper-body override and closed-loop
velocity correction.

The reference's root velocity (heading frame) is the command. When the reference sets
`upper_body_override`, waist and arm targets come from the reference while the policy keeps
balancing with the legs. The correction closes the loop on the estimated base velocity, because
the bare holosoma policies reach only ~80 % of the commanded speed (docs/robot_facts.md).
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
from g1_control.types import CommandLimits, EstimatedState, JointReference, MotorCommand, RobotState


@dataclass
class VelocityCorrectionConfig:
    """Command shaping so that the achieved velocity follows the operator's command.

    policy_cmd = ff * cmd + ki * integral(cmd - v_est), on vx, vy and wz, clamped to the
    policy's command ranges. The feedforward comes from the policy's measured speed ratio; the
    integral removes what is left. The integral resets while the command is near zero.
    """

    enabled: bool = True
    feedforward: tuple[float, float, float] = (1.0, 1.5, 1.0)
    ki: tuple[float, float, float] = (2.0, 2.0, 1.0)
    integral_limit: tuple[float, float, float] = (0.5, 0.7, 0.4)
    velocity_filter_tau_s: float = 0.1


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

    def reset(self) -> None:
        self.integral[:] = 0.0
        self.v_filtered[:] = 0.0

    def __call__(self, cmd: np.ndarray, v_est: np.ndarray | None) -> np.ndarray:
        """cmd and v_est are (vx, vy, wz) in the heading frame."""
        if not self.config.enabled or v_est is None:
            return cmd
        # Per axis on Python floats (three values; numpy's per-call cost would dominate).
        alpha, dt = self._alpha, self.dt_s
        out = cmd.tolist()
        integral, v_filtered = self.integral.tolist(), self.v_filtered.tolist()
        for i, (c, v) in enumerate(zip(out, v_est.tolist())):
            vf = v_filtered[i] = v_filtered[i] + alpha * (v - v_filtered[i])
            if abs(c) > 0.05:  # moving on this axis
                limit = self._limit[i]
                integral[i] = min(max(integral[i] + (c - vf) * dt * self._ki[i], -limit), limit)
                out[i] = self._ff[i] * c + integral[i]
            else:
                integral[i] = 0.0
        self.integral[:] = integral
        self.v_filtered[:] = v_filtered
        return np.array(out)


class LocomotionPolicyTracker(Tracker):
    """Runs a velocity-command locomotion policy (e.g. holosoma's) at spec.rate_hz."""

    def __init__(self, spec: PolicySpec, correction: VelocityCorrectionConfig | None = None):
        if spec.kind != "locomotion":
            raise ValueError(f"policy '{spec.name}' is a {spec.kind} policy, not a locomotion policy")
        self.spec = spec
        self.dt_s = 1.0 / spec.rate_hz
        self.runner = OnnxRunner(spec.onnx_path, spec.input_name)
        self.obs = ObservationBuilder(spec.observation)
        self.corrector = VelocityCorrector(correction or VelocityCorrectionConfig(), self.dt_s)
        self.velocity_estimate: np.ndarray | None = None
        """(vx, vy, wz) in the heading frame, from the state estimator (observe())."""
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
        self._upper_body = np.array(g1.UPPER_BODY_JOINTS)
        # Observation inputs, reused every tick (the builder copies them into its own vector).
        self._cos_phase, self._sin_phase = np.zeros(2), np.zeros(2)
        self._dof_pos = np.zeros(g1.NUM_JOINTS)
        self._values: dict[str, np.ndarray] = {"actions": self.last_action, "cos_phase": self._cos_phase,
                                               "sin_phase": self._sin_phase, "dof_pos": self._dof_pos}

    def observe(self, estimate: EstimatedState) -> None:
        self.velocity_estimate = estimate.heading_velocity

    @property
    def policy_command(self) -> np.ndarray:
        return self.last_policy_command

    @property
    def command_limits(self) -> CommandLimits:
        return self.spec.command_limits

    def reset(self, state: RobotState | None = None) -> None:
        self.last_action[:] = 0.0
        self.corrector.reset()
        self.obs.reset()
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
        v = self._values
        v["base_ang_vel"] = state.imu_gyro_radps
        v["command_ang_vel"] = cmd[2:3]
        v["command_lin_vel"] = cmd[0:2]
        np.cos(self._phase, out=self._cos_phase)
        np.sin(self._phase, out=self._sin_phase)
        np.subtract(state.q_rad, self.spec.default_q_rad, out=self._dof_pos)
        v["dof_vel"] = state.dq_radps
        v["projected_gravity"] = projected_gravity(state.imu_quat_wxyz)
        action = self.runner(self.obs.build(v))
        clip = self.spec.action_clip
        np.minimum(np.maximum(action, -clip, out=action), clip, out=action)  # np.clip's result, cheaper
        np.copyto(self.last_action, action)
        out = self._command
        np.multiply(self.last_action, self.spec.action_scale, out=out.q_rad)
        out.q_rad += self.spec.default_q_rad
        if reference.upper_body_override:
            out.q_rad[self._upper_body] = reference.q_rad[self._upper_body]
        return out
