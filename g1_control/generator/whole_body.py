"""Whole-body references for the whole-body controller: sampled trajectories and the IK that makes
their poses.

WholeBodyTrajectory: root pose, joint angles, the contact schedule and (optionally) the known hand
forces of a held object, sampled in time and played back through cubic splines (joint and root
velocities smooth and exact). Every sample is a PHASE_WHOLE_BODY reference.

WholeBodyIK: damped least squares on the floating-base configuration with the joint limits inside
the iteration: a joint at its limit whose step would push it further is locked (its column
removed) and the step solved again, so the other joints make up for it (a squat past the ankle's
dorsiflexion limit leans the trunk instead of leaving the feet off their targets; clipping after
the step left the soles 1.3 cm off, issue 17 investigation). Targets: both soles (pose), CoM xy,
pelvis height (and a one-sided cap: straight knees are singular for the tracker) and orientation,
hand points and orientations, posture as a weak regulariser.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from g1_control.errors import WbcConfigError
from g1_control.robot import g1
from g1_control.robot.dynamics import SOLE_FRAMES, build_model
from g1_control.rotations import quat_to_rot, rot_to_rpy, rotation_error, rpy_to_quat
from g1_control.types import PHASE_WHOLE_BODY, JointReference


def smoothstep(x: np.ndarray | float) -> np.ndarray:
    """Quintic 0 -> 1 with zero velocity and acceleration at both ends."""
    x = np.clip(x, 0.0, 1.0)
    return x**3 * (10 - 15 * x + 6 * x * x)


@dataclass
class WholeBodyTrajectory:
    """Samples of a whole-body reference; sample(t) interpolates with cubic splines."""

    name: str
    t_s: np.ndarray
    root_pos_w_m: np.ndarray
    root_rpy_rad: np.ndarray
    q_rad: np.ndarray
    contacts: np.ndarray
    """(n, 2) bool per sample; held constant from one sample to the next."""
    extras: dict = field(default_factory=dict)
    hand_forces_w_n: np.ndarray | None = None
    """(n, 2, 3) known forces on the (left, right) hand (JointReference.hand_forces_w_n), linear
    between samples; None: no hand forces."""

    def __post_init__(self) -> None:
        from scipy.interpolate import CubicSpline

        n = len(self.t_s)
        shapes = {"root_pos_w_m": (n, 3), "root_rpy_rad": (n, 3), "q_rad": (n, g1.NUM_JOINTS), "contacts": (n, 2)}
        for name, shape in shapes.items():
            if getattr(self, name).shape != shape:
                raise WbcConfigError(f"WholeBodyTrajectory.{name} has shape {getattr(self, name).shape}; expected {shape}")
        if self.hand_forces_w_n is not None and self.hand_forces_w_n.shape != (n, 2, 3):
            raise WbcConfigError(f"WholeBodyTrajectory.hand_forces_w_n has shape {self.hand_forces_w_n.shape}; "
                                 f"expected {(n, 2, 3)}")
        if n < 2 or np.any(np.diff(self.t_s) <= 0):
            raise WbcConfigError("WholeBodyTrajectory needs at least 2 samples at increasing times")
        if not np.all(self.contacts.any(axis=1)):
            raise WbcConfigError("WholeBodyTrajectory has samples with no foot in contact")
        # One spline over all 35 columns (root xyz, root rpy, joints): two evaluations per sample.
        self._spline = CubicSpline(self.t_s, np.hstack([self.root_pos_w_m, self.root_rpy_rad, self.q_rad]),
                                   bc_type="clamped")
        self._last: tuple[float, JointReference] | None = None

    @property
    def duration_s(self) -> float:
        return float(self.t_s[-1])

    def sample(self, t_s: float, out: JointReference | None = None) -> JointReference:
        out = out or JointReference()
        if self._last is not None and self._last[0] == t_s:  # generator and retargeter ask for the same tick
            copy_reference(self._last[1], out)
            return out
        t = float(np.clip(t_s, self.t_s[0], self.t_s[-1]))
        x, dx = self._spline(t), self._spline(t, 1)
        out.t_s = t_s
        out.q_rad[:] = x[6:]
        out.dq_radps[:] = dx[6:]
        out.root_pos_w_m[:] = x[:3]
        rpy, drpy = x[3:6], dx[3:6]
        out.root_quat_wxyz[:] = rpy_to_quat(rpy)
        vel_w = dx[:3]
        c, s = np.cos(rpy[2]), np.sin(rpy[2])
        out.root_linvel_h_mps[:] = (c * vel_w[0] + s * vel_w[1], -s * vel_w[0] + c * vel_w[1], vel_w[2])
        # ZYX Euler rates -> world angular velocity -> heading frame
        _, p, y = rpy
        w_world = np.array([-np.sin(y) * drpy[1] + np.cos(y) * np.cos(p) * drpy[0],
                            np.cos(y) * drpy[1] + np.sin(y) * np.cos(p) * drpy[0],
                            drpy[2] - np.sin(p) * drpy[0]])
        out.root_angvel_h_radps[:] = (c * w_world[0] + s * w_world[1], -s * w_world[0] + c * w_world[1], w_world[2])
        k = min(max(int(np.searchsorted(self.t_s, t, side="right")) - 1, 0), len(self.t_s) - 1)
        out.contacts[:] = self.contacts[k]
        out.phase = PHASE_WHOLE_BODY
        out.upper_body_override = True
        out.pelvis_height_m = None
        if self.hand_forces_w_n is None:
            out.hand_forces_w_n[:] = 0.0
        else:
            k1 = min(k + 1, len(self.t_s) - 1)
            w = 0.0 if k1 == k else (t - self.t_s[k]) / (self.t_s[k1] - self.t_s[k])
            out.hand_forces_w_n[:] = (1 - w) * self.hand_forces_w_n[k] + w * self.hand_forces_w_n[k1]
        if self._last is None:
            self._last = (t_s, JointReference())
        self._last = (t_s, self._last[1])
        copy_reference(out, self._last[1])
        return out


def copy_reference(src: JointReference, dst: JointReference) -> None:
    dst.copy_from(src)


def trajectory_from_configurations(name: str, t: np.ndarray, qs: np.ndarray, contacts: np.ndarray,
                                   hand_forces_w_n: np.ndarray | None = None, **extras) -> WholeBodyTrajectory:
    """From pinocchio configurations (n, 36: xyz, quaternion xyzw, joints) to a trajectory."""
    rpy = np.zeros((len(t), 3))
    for k, qk in enumerate(qs):
        x, y, z, w = qk[3:7]
        rpy[k] = rot_to_rpy(quat_to_rot(np.array([w, x, y, z])))
    rpy[:, 2] = np.unwrap(rpy[:, 2])
    return WholeBodyTrajectory(name, np.asarray(t, dtype=float), qs[:, :3].copy(), rpy, qs[:, 7:].copy(),
                               np.asarray(contacts, dtype=bool), dict(extras), hand_forces_w_n)


LEG_LIGHT_POSTURE_WEIGHT = np.where(np.isin(np.arange(g1.NUM_JOINTS), g1.LEG_JOINTS), 0.002, 0.05)
"""The legs are fixed by the feet and pelvis targets; a posture pull as strong as the upper body's
would leave a 15 cm crouch 2 cm short."""

LIMIT_MARGIN_RAD = 0.02
"""Poses keep this far inside the joint limits."""


class WholeBodyIK:
    """Damped least squares on the floating-base configuration (module docstring)."""

    def __init__(self, variant: g1.Variant = g1.G1_29DOF):
        """variant: the G1 whose poses are solved for; the joints it lacks stay at 0 (locked)."""
        import pinocchio as pin

        self.pin = pin
        self.variant = variant
        self._locked = np.flatnonzero(~variant.active_mask)
        self.model = build_model()
        self.data = self.model.createData()
        self.sole_ids = [self.model.getFrameId(n) for n in SOLE_FRAMES]
        self.pelvis_id = self.model.getFrameId(g1.BASE_BODY)
        self._posture_jac = np.zeros((g1.NUM_JOINTS, self.model.nv))
        self._posture_jac[:, 6:] = np.eye(g1.NUM_JOINTS)

    def nominal(self) -> np.ndarray:
        """Default pose with the soles flat on z = 0 and the pelvis above the origin."""
        q = np.concatenate([[0, 0, 0, 0, 0, 0, 1.0], g1.DEFAULT_Q_RAD])
        self.pin.framesForwardKinematics(self.model, self.data, q)
        q[2] = -self.data.oMf[self.sole_ids[0]].translation[2]
        return q

    def frame_pose(self, q: np.ndarray, name: str) -> tuple[np.ndarray, np.ndarray]:
        self.pin.framesForwardKinematics(self.model, self.data, q)
        placement = self.data.oMf[self.model.getFrameId(name)]
        return placement.translation.copy(), placement.rotation.copy()

    def com(self, q: np.ndarray) -> np.ndarray:
        return self.pin.centerOfMass(self.model, self.data, q).copy()

    def solve(self, q0: np.ndarray, soles: list[tuple[np.ndarray, np.ndarray]], com_xy: np.ndarray | None,
              pelvis_z: float | None, pelvis_rot: np.ndarray, posture: np.ndarray, *,
              hands: tuple[tuple[str, np.ndarray], ...] | list = (), hand_weight: float = 10.0,
              hand_rot: tuple[tuple[str, np.ndarray], ...] | list = (), hand_rot_weight: float = 10.0,
              pelvis_rot_weight=(10.0, 10.0, 10.0), posture_weight: np.ndarray | float | None = None,
              sole_weight: float | np.ndarray = 100.0, com_weight: float = 30.0, pelvis_z_weight: float = 30.0,
              pelvis_z_max: float | None = None, iterations: int = 30, tol: float = 1e-6,
              damping: float = 1e-6, margin_rad: float | np.ndarray = LIMIT_MARGIN_RAD) -> np.ndarray:
        """The configuration (pinocchio q) nearest `q0` that meets the targets in the weighted
        least-squares sense, every joint within its limits (less margin_rad).

        soles: (position, rotation) per sole frame; com_xy / pelvis_z: None to leave free;
        pelvis_z_max: a one-sided cap on the pelvis height; hands / hand_rot: (frame name, target).
        sole_weight: one number, or (2, 6) per sole (position, rotation) - e.g. a swing foot whose
        pitch may give; margin_rad: one number or per joint (29,).
        """
        pin, m, d = self.pin, self.model, self.data
        if posture_weight is None:
            posture_weight = LEG_LIGHT_POSTURE_WEIGHT
        lo, hi = g1.Q_MIN_RAD + margin_rad, g1.Q_MAX_RAD - margin_rad
        if self._locked.size:  # joints the variant lacks: held at 0, never moved
            lo, hi = np.array(lo, dtype=float), np.array(hi, dtype=float)
            lo[self._locked] = hi[self._locked] = 0.0
        q = q0.copy()
        q[7:] = np.clip(q[7:], lo, hi)
        lwa = pin.LOCAL_WORLD_ALIGNED
        nv = m.nv
        w_post = np.broadcast_to(np.asarray(posture_weight, dtype=float), (g1.NUM_JOINTS,))
        hand_ids = [(m.getFrameId(name), target) for name, target in hands]
        hand_rot_ids = [(m.getFrameId(name), rot) for name, rot in hand_rot]
        eye = damping * np.eye(nv)
        w_soles = np.broadcast_to(np.asarray(sole_weight, dtype=float), (2, 6))
        for _ in range(iterations):
            pin.computeJointJacobians(m, d, q)
            pin.updateFramePlacements(m, d)
            rows, errs, weights = [], [], []
            for i, (fid, (pos, rot)) in enumerate(zip(self.sole_ids, soles)):
                rows.append(pin.getFrameJacobian(m, d, fid, lwa))
                errs.append(np.concatenate([pos - d.oMf[fid].translation, rotation_error(rot, d.oMf[fid].rotation)]))
                weights.append(w_soles[i])
            jp = pin.getFrameJacobian(m, d, self.pelvis_id, lwa)
            pelvis_now = d.oMf[self.pelvis_id]
            rows.append(jp[3:])
            errs.append(rotation_error(pelvis_rot, pelvis_now.rotation))
            weights.append(np.asarray(pelvis_rot_weight, dtype=float))
            if pelvis_z is not None:
                rows.append(jp[2:3])
                errs.append(np.array([pelvis_z - pelvis_now.translation[2]]))
                weights.append(np.array([pelvis_z_weight]))
            if pelvis_z_max is not None and pelvis_now.translation[2] > pelvis_z_max:
                rows.append(jp[2:3])
                errs.append(np.array([pelvis_z_max - pelvis_now.translation[2]]))
                weights.append(np.array([300.0]))
            if com_xy is not None:
                jc = pin.jacobianCenterOfMass(m, d, q)
                rows.append(jc[:2])
                errs.append(com_xy - d.com[0][:2])
                weights.append(np.full(2, com_weight))
            for fid, target in hand_ids:
                rows.append(pin.getFrameJacobian(m, d, fid, lwa)[:3])
                errs.append(target - d.oMf[fid].translation)
                weights.append(np.full(3, hand_weight))
            for fid, rot in hand_rot_ids:
                rows.append(pin.getFrameJacobian(m, d, fid, lwa)[3:])
                errs.append(rotation_error(rot, d.oMf[fid].rotation))
                weights.append(np.full(3, hand_rot_weight))
            rows.append(self._posture_jac)
            errs.append(posture - q[7:])
            weights.append(w_post)
            jac, e, w = np.vstack(rows), np.concatenate(errs), np.concatenate(weights)
            if self._locked.size:
                jac[:, 6 + self._locked] = 0.0
            jw = jac.T * w
            h, g = jw @ jac + eye, jw @ e
            dv = np.linalg.solve(h, g)
            # Joints at a limit whose step pushes them out are locked and the step solved again.
            qj = q[7:] + dv[6:]
            push = ((qj < lo) & (dv[6:] < 0)) | ((qj > hi) & (dv[6:] > 0))
            if push.any():
                free = np.ones(nv, dtype=bool)
                for _k in range(4):
                    free[6:][push] = False
                    dv[:] = 0.0
                    dv[free] = np.linalg.solve(h[np.ix_(free, free)], g[free])
                    qj = q[7:] + dv[6:]
                    push = ((qj < lo) & (dv[6:] < 0)) | ((qj > hi) & (dv[6:] > 0))
                    if not push.any():
                        break
            q = pin.integrate(m, q, dv)
            q[7:] = np.clip(q[7:], lo, hi)
            if np.abs(dv).max() < tol:
                break
        return q


def keyframe_trajectory(name: str, keyframes: list[tuple[float, np.ndarray]], *, dt_s: float = 0.02,
                        contacts: np.ndarray | None = None, hand_forces=None, **extras) -> WholeBodyTrajectory:
    """Quintic blends in configuration space between keyframes (time, pinocchio q); a hold is the
    same configuration at a later time. contacts: (2,) both samples' schedule (default both feet);
    hand_forces(t) -> (2, 3): the known hand forces at time t."""
    times = np.array([k[0] for k in keyframes], dtype=float)
    qs = np.array([k[1] for k in keyframes])
    if np.any(np.diff(times) <= 0):
        raise WbcConfigError(f"keyframe_trajectory '{name}': keyframe times must increase; got {times.tolist()}")
    t = np.arange(0.0, times[-1] + 1e-9, dt_s)
    if t[-1] < times[-1] - 1e-9:
        t = np.append(t, times[-1])
    out = np.zeros((len(t), qs.shape[1]))
    j = np.clip(np.searchsorted(times, t, side="right") - 1, 0, len(times) - 2)
    s = smoothstep((t - times[j]) / (times[j + 1] - times[j]))
    out[:] = qs[j] + s[:, None] * (qs[j + 1] - qs[j])
    out[:, 3:7] /= np.linalg.norm(out[:, 3:7], axis=1, keepdims=True)
    c = np.ones((len(t), 2), dtype=bool) if contacts is None else np.broadcast_to(contacts, (len(t), 2)).copy()
    forces = None if hand_forces is None else np.array([hand_forces(tk) for tk in t])
    return trajectory_from_configurations(name, t, out, c, forces, **extras)


__all__ = ["LEG_LIGHT_POSTURE_WEIGHT", "WholeBodyIK", "WholeBodyTrajectory", "copy_reference", "keyframe_trajectory",
           "smoothstep", "trajectory_from_configurations"]
