"""Velocity-command locomotion policy as a Tracker, with an upper-body override and closed-loop
velocity correction.

The reference's root velocity (heading frame) is the command. When the reference sets
`upper_body_override`, waist and arm targets come from the reference while the policy keeps
balancing with the legs. The correction closes the loop on the estimated base velocity, because
the bare holosoma policies reach only ~80 % of the commanded speed (FACTS.md).
"""

from __future__ import annotations

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
        self._ff = np.array(config.feedforward)
        self._ki = np.array(config.ki)
        self._limit = np.array(config.integral_limit)
        self.integral = np.zeros(3)
        self.v_filtered = np.zeros(3)

    def reset(self) -> None:
        self.integral[:] = 0.0
        self.v_filtered[:] = 0.0

    def __call__(self, cmd: np.ndarray, v_est: np.ndarray | None) -> np.ndarray:
        """cmd and v_est are (vx, vy, wz) in the heading frame."""
        if not self.config.enabled or v_est is None:
            return cmd
        alpha = self.dt_s / (self.config.velocity_filter_tau_s + self.dt_s)
        self.v_filtered += alpha * (v_est - self.v_filtered)
        moving = np.abs(cmd) > 0.05
        self.integral = np.where(moving, self.integral + (cmd - self.v_filtered) * self.dt_s * self._ki, 0.0)
        np.clip(self.integral, -self._limit, self._limit, out=self.integral)
        return np.where(moving, self._ff * cmd + self.integral, cmd)


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
        self.last_action = np.zeros(g1.NUM_JOINTS)
        self.last_policy_command = np.zeros(3)
        self._phase = np.zeros(2)
        self._standing = True
        self._command = MotorCommand(q_rad=spec.default_q_rad.copy(), kp=spec.kp.copy(), kd=spec.kd.copy())
        self._values: dict[str, np.ndarray] = {}

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
        self._phase = np.fmod(self._phase + 2 * np.pi * self.dt_s / phase.period_s + np.pi, 2 * np.pi) - np.pi
        if np.linalg.norm(cmd[:2]) < phase.stand_threshold and abs(cmd[2]) < phase.stand_threshold:
            self._phase[:] = np.pi  # both feet in the same phase: stand
            self._standing = True
        elif self._standing:
            self._phase = phase.offsets_rad.copy()  # start the gait from its initial phase
            self._standing = False

    def act(self, reference: JointReference, state: RobotState) -> MotorCommand:
        cmd = np.array([reference.root_linvel_h_mps[0], reference.root_linvel_h_mps[1], reference.root_angvel_h_radps[2]])
        cmd = self.corrector(cmd, self.velocity_estimate)
        cmd = np.clip(cmd, self._ranges[:, 0], self._ranges[:, 1])
        self.last_policy_command = cmd
        self._advance_phase(cmd)
        v = self._values
        v["actions"] = self.last_action
        v["base_ang_vel"] = state.imu_gyro_radps
        v["command_ang_vel"] = cmd[2:3]
        v["command_lin_vel"] = cmd[0:2]
        v["cos_phase"] = np.cos(self._phase)
        v["sin_phase"] = np.sin(self._phase)
        v["dof_pos"] = state.q_rad - self.spec.default_q_rad
        v["dof_vel"] = state.dq_radps
        v["projected_gravity"] = projected_gravity(state.imu_quat_wxyz)
        action = self.runner(self.obs.build(v))
        np.clip(action, -self.spec.action_clip, self.spec.action_clip, out=action)
        self.last_action = action.astype(float)
        out = self._command
        out.q_rad[:] = self.spec.default_q_rad + self.spec.action_scale * self.last_action
        if reference.upper_body_override:
            ub = list(g1.UPPER_BODY_JOINTS)
            out.q_rad[ub] = reference.q_rad[ub]
        return out
