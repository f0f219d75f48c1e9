"""The whole-body controller as a Tracker: act(JointReference, RobotState) -> MotorCommand.

Per tick:
  1. floating-base state without ground truth: orientation and angular velocity from the IMU,
     linear velocity from the project's StateEstimator (leg kinematics + accelerometer), position
     from leg odometry anchored at the stance feet (odometry.py);
  2. the reference's full configuration (root pose + joints) through forward kinematics gives the
     task targets: CoM, pelvis and torso orientation, swing-foot poses, hand positions, posture;
  3. the CoM's horizontal target becomes a CoM acceleration by capture-point feedback clipped to
     the support polygon (capture_point.py);
  4. the inverse-dynamics QP (qp.py) returns accelerations, contact wrenches and torques;
  5. the motor command: feedforward torque plus q/dq targets one tick ahead along the QP's
     accelerations, with gains well below the default stiffness (see WbcConfig.kp_scale).

Contact flags come from the reference (JointReference.contacts: the contact schedule). A foot
that touches down takes load gradually (contact_ramp_s), so torques do not jump.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from g1_control.errors import WbcConfigError, WbcSolveError
from g1_control.estimation.estimator import StateEstimator
from g1_control.interfaces import Tracker
from g1_control.robot import g1
from g1_control.robot.dynamics import WbcModel
from g1_control.rotations import quat_to_rot, yaw_of
from g1_control.trackers.wbc import capture_point as cp
from g1_control.trackers.wbc.odometry import BaseOdometry
from g1_control.trackers.wbc.qp import IdSolution, InverseDynamicsQP, QpConfig
from g1_control.trackers.wbc.tasks import (
    AccelerationTask,
    TaskGains,
    orientation_task,
    position_task,
    posture_task,
)
from g1_control.types import JointReference, MotorCommand, RobotState


@dataclass(frozen=True)
class WbcConfig:
    rate_hz: float = 250.0
    """The loop's tracker rate; used only for the first tick's time step."""
    com_height: TaskGains = field(default_factory=lambda: TaskGains(100.0, 20.0, 100.0))
    com_xy_weight: float = 100.0
    capture_point_gain: float = 2.0
    """k in p = p_ref + (1 + k)(xi - xi_ref): capture-point error decays as exp(-k w t)."""
    pelvis_orientation: TaskGains = field(default_factory=lambda: TaskGains(150.0, 25.0, 30.0))
    torso_orientation: TaskGains = field(default_factory=lambda: TaskGains(100.0, 20.0, 10.0))
    swing_foot: TaskGains = field(default_factory=lambda: TaskGains(400.0, 40.0, 100.0))
    hands: TaskGains = field(default_factory=lambda: TaskGains(100.0, 20.0, 3.0))
    posture: TaskGains = field(default_factory=lambda: TaskGains(100.0, 20.0, 1.0))
    clip_cop_to_support: bool = False
    """Clip the capture-point CoP into the support polygon before it becomes the CoM task. Off,
    the QP gets the unclipped CoM acceleration and meets what the feet cannot give with angular
    momentum (trunk and arm rotation), trading it against the orientation tasks."""
    contact_ramp_s: float = 0.06
    """After touchdown a foot's normal-force allowance grows from zero to full over this time."""
    liftoff_unload_s: float = 0.015
    """After the schedule lifts a foot, it stays a (shrinking) contact this long: its normal-force
    allowance falls to zero first, so the other leg's torques take the load without a jump."""
    kp_scale: float = 0.3
    kd_scale: float = 0.5
    """Motor-law gains as fractions of g1.KP_DEFAULT / KD_DEFAULT (10 Hz, damping ratio 2 on the
    armature). The torque feedforward does the work; the drivers' PD (run at their own high rate)
    only holds the joints along the QP's one-tick-ahead prediction between controller ticks and
    absorbs model error. At full default stiffness the PD would override the QP's balance torques."""
    qp: QpConfig = field(default_factory=QpConfig)

    def __post_init__(self) -> None:
        if self.rate_hz <= 0:
            raise WbcConfigError(f"WbcConfig.rate_hz must be > 0; got {self.rate_hz}")
        for name in ("kp_scale", "kd_scale", "contact_ramp_s", "liftoff_unload_s", "capture_point_gain", "com_xy_weight"):
            value = getattr(self, name)
            if not (np.isfinite(value) and value >= 0):
                raise WbcConfigError(f"WbcConfig.{name} must be a finite number >= 0; got {value}")


@dataclass
class WbcDiagnostics:
    """What the last tick computed (for logs, tests and the benchmark)."""

    base_pos_w_m: np.ndarray = field(default_factory=lambda: np.zeros(3))
    com_m: np.ndarray = field(default_factory=lambda: np.zeros(3))
    com_ref_m: np.ndarray = field(default_factory=lambda: np.zeros(3))
    cop_des_xy_m: np.ndarray = field(default_factory=lambda: np.zeros(2))
    solution: IdSolution | None = None
    solve_failures: int = 0
    """Ticks whose first QP had no solution (then retried relaxed)."""
    unsolved_ticks: int = 0
    """Ticks where the relaxed QP failed too and the previous command was repeated."""
    ticks: int = 0


class WholeBodyTracker(Tracker):
    def __init__(self, config: WbcConfig | None = None, variant: g1.Variant = g1.G1_29DOF, hands: str = "none"):
        """variant, hands: the G1 it controls; its dynamics come from that robot's model (WbcModel)."""
        import pinocchio as pin

        self._pin = pin
        self.config = config or WbcConfig()
        self.dyn = WbcModel(variant, hands)
        self.qp = InverseDynamicsQP(self.dyn.nv, self.config.qp)
        self.estimator = StateEstimator()
        self.odometry = BaseOdometry()
        self.ref_data = self.dyn.model.createData()
        self.diagnostics = WbcDiagnostics()
        self._corners = self.config.qp.foot.corners_local_m()
        self._kp = self.config.kp_scale * g1.KP_DEFAULT
        self._kd = self.config.kd_scale * g1.KD_DEFAULT
        self._command = MotorCommand(kp=self._kp.copy(), kd=self._kd.copy())
        self._q = np.zeros(self.dyn.nq)
        self._v = np.zeros(self.dyn.nv)
        self._q_ref = np.zeros(self.dyn.nq)
        self._v_ref = np.zeros(self.dyn.nv)
        self.reset()

    # -- lifecycle ---------------------------------------------------------------------------------
    def reset(self, state: RobotState | None = None) -> None:
        self.estimator.reset(state)
        self.qp.reset()
        self._last_t: float | None = None
        self._started = False
        self._stance_since = np.zeros(2)
        self._swing_since = np.full(2, -np.inf)
        self._prev_stance = np.ones(2, dtype=bool)
        self._com_vel_ref_prev: np.ndarray | None = None
        self._com_acc_ref = np.zeros(3)
        self._frame_vel_ref_prev: dict[int, np.ndarray] = {}
        self.diagnostics = WbcDiagnostics()

    def _start(self, reference: JointReference, state: RobotState) -> None:
        """First tick: the odometry's world frame is the reference's; the robot starts at the
        reference's root xy, its height set by the lower sole resting on the ground (z = 0)."""
        offsets = self._sole_offsets(state.imu_quat_wxyz, state.q_rad)
        lowest = offsets[:, 2].min()
        base = np.array([reference.root_pos_w_m[0], reference.root_pos_w_m[1], -lowest])
        self.odometry.reset(base, offsets)
        self._stance_since[:] = -np.inf
        self._prev_stance[:] = reference.contacts
        self._started = True

    def _sole_offsets(self, quat_wxyz: np.ndarray, q_rad: np.ndarray) -> np.ndarray:
        pin, m, d = self._pin, self.dyn.model, self.ref_data
        q = np.concatenate([np.zeros(3), [quat_wxyz[1], quat_wxyz[2], quat_wxyz[3], quat_wxyz[0]], q_rad])
        pin.framesForwardKinematics(m, d, q)
        return np.array([d.oMf[fid].translation for fid in self.dyn.sole_ids])

    # -- the tick --------------------------------------------------------------------------------------
    def act(self, reference: JointReference, state: RobotState) -> MotorCommand:
        pin, cfg, dyn = self._pin, self.config, self.dyn
        if not self._started:
            self._start(reference, state)
        dt = 1.0 / cfg.rate_hz if self._last_t is None else max(1e-4, state.t_s - self._last_t)
        self._last_t = state.t_s
        scheduled = np.asarray(reference.contacts, dtype=bool)
        if not scheduled.any():
            raise WbcConfigError("JointReference.contacts has no foot in contact; the controller needs at "
                                 "least one stance foot (flight phases are not supported)")
        for i in range(2):
            if scheduled[i] and not self._prev_stance[i]:
                self._stance_since[i] = state.t_s
            elif not scheduled[i] and self._prev_stance[i]:
                self._swing_since[i] = state.t_s
        self._prev_stance[:] = scheduled
        load = np.clip((state.t_s - self._stance_since) / max(cfg.contact_ramp_s, 1e-6), 0.0, 1.0)
        unloading = ~scheduled & (state.t_s - self._swing_since < cfg.liftoff_unload_s)
        load[unloading] = 1.0 - (state.t_s - self._swing_since[unloading]) / max(cfg.liftoff_unload_s, 1e-6)
        stance = scheduled | unloading

        # 1. floating-base state
        # Leg-kinematics velocity from the scheduled stance feet (the lower foot is not the stance
        # foot on a step: with it, a trailing foot swinging up read as the body falling, measured).
        est = self.estimator.update(state, scheduled if scheduled.all() or not stance.all() else stance)
        quat = state.imu_quat_wxyz
        rot = quat_to_rot(quat)
        q, v = self._q, self._v
        q[3:7] = (quat[1], quat[2], quat[3], quat[0])
        q[7:] = state.q_rad
        q[:3] = self.odometry.base_pos_w_m
        v[:3] = rot.T @ est.base_linvel_w_mps
        v[3:6] = state.imu_gyro_radps
        v[6:] = state.dq_radps
        dyn.hand_forces_w_n[:] = reference.hand_forces_w_n
        dyn.update(q, v)
        sole_pos_before = np.array([dyn.data.oMf[f].translation for f in dyn.sole_ids])
        offsets = sole_pos_before - q[:3]
        base_prev = q[:3].copy()
        base = self.odometry.update(dt, est.base_linvel_w_mps, offsets, stance)
        shift = base - base_prev  # positions computed before the odometry step move with the base
        q[:3] = base

        # 2. reference kinematics
        qr, vr, rd = self._q_ref, self._v_ref, self.ref_data
        rq = reference.root_quat_wxyz
        qr[:3] = reference.root_pos_w_m
        qr[3:7] = (rq[1], rq[2], rq[3], rq[0])
        qr[7:] = reference.q_rad
        rot_ref = quat_to_rot(rq)
        yaw_ref = yaw_of(rq)
        c, s = np.cos(yaw_ref), np.sin(yaw_ref)
        lin_h, ang_h = reference.root_linvel_h_mps, reference.root_angvel_h_radps
        lin_w = np.array([c * lin_h[0] - s * lin_h[1], s * lin_h[0] + c * lin_h[1], lin_h[2]])
        ang_w = np.array([c * ang_h[0] - s * ang_h[1], s * ang_h[0] + c * ang_h[1], ang_h[2]])
        vr[:3] = rot_ref.T @ lin_w
        vr[3:6] = rot_ref.T @ ang_w
        vr[6:] = reference.dq_radps
        pin.forwardKinematics(dyn.model, rd, qr, vr)
        pin.updateFramePlacements(dyn.model, rd)
        pin.centerOfMass(dyn.model, rd, qr, vr, False)
        com_ref, com_vel_ref = rd.com[0].copy(), rd.vcom[0].copy()
        if self._com_vel_ref_prev is not None:
            raw = (com_vel_ref - self._com_vel_ref_prev) / dt
            self._com_acc_ref += min(1.0, dt / 0.02) * (raw - self._com_acc_ref)
        self._com_vel_ref_prev = com_vel_ref

        # 3. balance: CoM acceleration from capture-point feedback
        com = dyn.com_m + shift
        com_vel = dyn.com_vel_mps
        sole_pos = sole_pos_before + shift
        sole_rot = np.array([dyn.data.oMf[f].rotation for f in dyn.sole_ids])
        ground_z = float(np.mean(sole_pos[stance, 2]))
        omega = cp.lipm_frequency(max(com[2] - ground_z, 0.2))
        cop_ref = com_ref[:2] - self._com_acc_ref[:2] / omega**2
        cop = cp.desired_cop(com[:2], com_vel[:2], com_ref[:2], com_vel_ref[:2], cop_ref, omega,
                             cfg.capture_point_gain)
        hull = cp.support_polygon(sole_pos, sole_rot, self._corners, stance)
        if cfg.clip_cop_to_support:
            cop = cp.project_into_polygon(cop, hull)
        h = cfg.com_height
        a_com = np.empty(3)
        a_com[:2] = omega**2 * (com[:2] - cop)
        a_com[2] = self._com_acc_ref[2] + h.kp * (com_ref[2] - com[2]) + h.kd * (com_vel_ref[2] - com_vel[2])
        tasks: list[AccelerationTask] = [
            AccelerationTask("com", dyn.com_jac, a_com - dyn.com_drift,
                             np.array([cfg.com_xy_weight, cfg.com_xy_weight, h.weight])),
        ]

        # 4. orientation, swing feet, hands, posture
        lwa = pin.LOCAL_WORLD_ALIGNED
        for fid, gains in ((dyn.pelvis_id, cfg.pelvis_orientation), (dyn.torso_id, cfg.torso_orientation)):
            ft = dyn.frame(fid)
            ref_rot = rd.oMf[fid].rotation
            ref_w = pin.getFrameVelocity(dyn.model, rd, fid, lwa).angular
            tasks.append(orientation_task("orientation", ft.jac_w[3:], ft.drift_w[3:], ft.rot_w, ft.vel_w[3:],
                                          ref_rot, ref_w, gains))
        for i, fid in enumerate(dyn.sole_ids):
            ref_v = pin.getFrameVelocity(dyn.model, rd, fid, lwa)
            # The swing foot's reference acceleration, by differencing its reference velocity
            # (a JointReference carries no accelerations); without it the foot lags, then overshoots.
            prev = self._frame_vel_ref_prev.get(fid)
            acc_ref = np.zeros(3) if prev is None else (ref_v.linear - prev) / dt
            self._frame_vel_ref_prev[fid] = ref_v.linear.copy()
            if stance[i]:
                continue
            ft = dyn.frame(fid)
            tasks.append(position_task("swing_foot", ft.jac_w[:3], ft.drift_w[:3], ft.pos_w_m + shift,
                                       ft.vel_w[:3], rd.oMf[fid].translation, ref_v.linear, acc_ref,
                                       cfg.swing_foot))
            tasks.append(orientation_task("swing_foot_rot", ft.jac_w[3:], ft.drift_w[3:], ft.rot_w, ft.vel_w[3:],
                                          rd.oMf[fid].rotation, ref_v.angular, cfg.swing_foot))
        if cfg.hands.weight > 0:
            for fid in dyn.hand_ids:
                ft = dyn.frame(fid)
                ref_v = pin.getFrameVelocity(dyn.model, rd, fid, lwa).linear
                tasks.append(position_task("hand", ft.jac_w[:3], ft.drift_w[:3], ft.pos_w_m + shift, ft.vel_w[:3],
                                           rd.oMf[fid].translation, ref_v, np.zeros(3), cfg.hands))
        tasks.append(posture_task(dyn.nv, state.q_rad, state.dq_radps, reference.q_rad, reference.dq_radps,
                                  cfg.posture))

        # 5. solve and command
        diag = self.diagnostics
        diag.ticks += 1
        diag.base_pos_w_m = base.copy()
        diag.com_m, diag.com_ref_m, diag.cop_des_xy_m = com, com_ref, cop
        try:
            sol = self.qp.solve(dyn, tasks, stance, load)
        except WbcSolveError:
            # Seen at touchdown: a foot landing fast cannot be stopped at once within the torque
            # and force limits while its load is still ramping in. Retry with the contact
            # allowed its full load and no velocity damping; failing that, keep the last command.
            diag.solve_failures += 1
            try:
                sol = self.qp.solve(dyn, tasks, stance, np.ones(2), contact_damping_per_s=0.0)
            except WbcSolveError:
                diag.unsolved_ticks += 1
                return self._command if diag.solution is not None else self._hold(state)
        diag.solution = sol
        out = self._command
        ddq = sol.ddq[6:]
        out.tau_nm[:] = sol.tau_nm
        out.dq_radps[:] = state.dq_radps + ddq * dt
        out.q_rad[:] = state.q_rad + (state.dq_radps + 0.5 * ddq * dt) * dt
        out.kp[:] = self._kp
        out.kd[:] = self._kd
        return out

    def _hold(self, state: RobotState) -> MotorCommand:
        """A tick without a QP solution: hold the measured posture with the default gains."""
        out = self._command
        out.tau_nm[:] = 0.0
        out.q_rad[:] = state.q_rad
        out.dq_radps[:] = 0.0
        out.kp[:] = g1.KP_DEFAULT
        out.kd[:] = g1.KD_DEFAULT
        return out
