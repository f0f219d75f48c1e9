"""WholeBodyIK: the offline whole-body IK that makes the poses of planned whole-body references
(generator/scripted.py, generator/goals/: footsteps, crouches, reaches, box handling).

Damped least squares on the floating-base configuration with the joint limits inside the
iteration: a joint at its limit whose step would push it further is locked (its column removed)
and the step solved again, so the other joints make up for it (a squat past the ankle's
dorsiflexion limit leans the trunk instead of leaving the feet off their targets; clipping after
the step left the soles 1.3 cm off, issue 17 investigation). Targets: both soles (pose), CoM xy,
pelvis height (and a one-sided cap: straight knees are singular for the tracker) and orientation,
hand points and orientations, posture as a weak regulariser.

The loop's per-tick IK is the QP of retargeter.py (IKRetargeter, behind stage.py's IKStage); this
one solves a pose to convergence, many iterations at a time, while a plan is made.
"""

from __future__ import annotations

import numpy as np

from g1_control.robot import g1
from g1_control.robot.dynamics import SOLE_FRAMES, build_model
from g1_control.rotations import rotation_error

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


__all__ = ["LEG_LIGHT_POSTURE_WEIGHT", "LIMIT_MARGIN_RAD", "WholeBodyIK"]
