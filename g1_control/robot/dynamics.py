"""The G1's rigid-body dynamics for the controller: pinocchio model with the motors' armature,
the frames the controller uses (soles, pelvis, torso, hands) and, per tick, everything the QP
needs: mass matrix, bias forces, frame Jacobians and their drift terms (J_dot v).

Configuration and velocity are pinocchio's: q = (x y z, qx qy qz qw, joints), v = (base linear
velocity in the base frame, base angular velocity in the base frame, joint velocities).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from g1_control.errors import RobotDescriptionError
from g1_control.robot import description, g1

SOLE_OFFSET_M = np.array([0.035, 0.0, -0.035])
"""Sole frame origin in the ankle-roll link: midway between the URDF's front (x 0.12) and rear
(x -0.05) contact spheres, on the plane their bottoms touch (centres z -0.03, radius 0.005)."""

SOLE_FRAMES = ("left_sole", "right_sole")
HAND_FRAMES = ("left_hand", "right_hand")
HAND_OFFSET_M = np.array([0.1, 0.0, 0.0])
"""Hand point in the wrist-yaw link: roughly the palm centre (the URDF's rubber hand extends ~0.1 m)."""


def build_model(hands: str = "none"):
    """pinocchio Model of the G1 (with `hands`: description.pinocchio_model) with armature and the
    controller's extra frames."""
    import pinocchio as pin

    model = pin.Model(description.pinocchio_model(hands))
    # MuJoCo (and the robot) have reflected rotor inertia on every joint; without it the
    # controller's mass matrix is wrong by up to 30 % on the distal joints.
    model.armature[6:] = g1.ARMATURE_KGM2
    for body, name, offset in ((g1.FOOT_BODIES[0], SOLE_FRAMES[0], SOLE_OFFSET_M),
                               (g1.FOOT_BODIES[1], SOLE_FRAMES[1], SOLE_OFFSET_M),
                               (g1.HAND_BODIES[0], HAND_FRAMES[0], HAND_OFFSET_M),
                               (g1.HAND_BODIES[1], HAND_FRAMES[1], HAND_OFFSET_M)):
        parent = model.getFrameId(body)
        frame = model.frames[parent]
        model.addFrame(pin.Frame(name, frame.parentJoint, parent,
                                 frame.placement * pin.SE3(np.eye(3), offset), pin.FrameType.OP_FRAME))
    return model


@dataclass
class FrameTerms:
    """One frame's kinematics at the current state (world-aligned axes unless noted)."""

    pos_w_m: np.ndarray
    rot_w: np.ndarray
    jac_w: np.ndarray
    """6 x nv, LOCAL_WORLD_ALIGNED: rows (linear, angular)."""
    drift_w: np.ndarray
    """6: classical acceleration at zero joint acceleration (J_dot v), LOCAL_WORLD_ALIGNED."""
    vel_w: np.ndarray
    """6: (linear m/s, angular rad/s), LOCAL_WORLD_ALIGNED."""


def build_variant_model(variant: g1.Variant, hands: str = "none"):
    """(full model, the variant's model): build_model(), and the same with the joints `variant`
    lacks locked at zero (pinocchio's reduced model: their links welded to their parents, the
    masses and frames kept; None for the 29-DoF G1). The frames keep their ids and names."""
    import pinocchio as pin

    full = build_model(hands)
    if variant.num_dof == g1.NUM_JOINTS:
        return full, None
    locked = [full.getJointId(g1.JOINT_NAMES[i]) for i in range(g1.NUM_JOINTS) if i not in variant.active_joints]
    reduced = pin.buildReducedModel(full, locked, pin.neutral(full))
    if [f.name for f in reduced.frames] != [f.name for f in full.frames]:
        raise RobotDescriptionError(f"pinocchio's {variant.name} model renumbered the G1's frames; the controller "
                                    "addresses frames of both models by one id")
    return full, reduced


class WbcModel:
    """Evaluates the dynamics terms the QP needs at one state; reuses its buffers.

    Every array is in the 29-DoF G1's coordinates (nv 35: base, then g1.JOINT_NAMES), whatever the
    variant, so that the controller and its QP serve every variant unchanged. For a variant without
    some joints (the 23-DoF G1), the terms are those of the variant's own model (build_variant_model:
    the joints it lacks locked), scattered into those coordinates: a locked joint's coordinate is
    decoupled from everything (unit inertia, no bias, no Jacobian column, no contact or gravity
    term), so the QP can neither use it nor feel it, and the rest is the reduced model's dynamics
    exactly. `model` stays the 29-DoF kinematic model (for references, whose locked joints are 0 on
    such a robot); `data` holds the kinematics of the last update() (of the variant's model: frame
    ids are the same in both).
    """

    def __init__(self, variant: g1.Variant = g1.G1_29DOF, hands: str = "none") -> None:
        """hands 'dex3': the G1 with Dex3-1 hands, fingers locked open (their mass and frames)."""
        import pinocchio as pin

        self._pin = pin
        self.variant = variant
        self.model, reduced = build_variant_model(variant, hands)
        self.dynamics_model = self.model if reduced is None else reduced
        """The variant's own model: the one update() evaluates."""
        self.data = self.dynamics_model.createData()
        self.nv = self.model.nv
        self.nq = self.model.nq
        self._reduced = reduced is not None
        active = np.array(variant.active_joints)
        self._qi = np.concatenate([np.arange(7), 7 + active])
        """Indices of the variant model's configuration in the 29-DoF one."""
        self._vi = np.concatenate([np.arange(6), 6 + active])
        """Indices of the variant model's velocity coordinates in the 29-DoF ones."""
        self._locked_v = np.setdiff1d(np.arange(self.nv), self._vi)
        self.mass_kg = float(sum(i.mass for i in self.model.inertias))
        self.sole_ids = tuple(self.model.getFrameId(n) for n in SOLE_FRAMES)
        self.hand_ids = tuple(self.model.getFrameId(n) for n in HAND_FRAMES)
        self.pelvis_id = self.model.getFrameId(g1.BASE_BODY)
        self.torso_id = self.model.getFrameId(g1.TORSO_BODY)
        self._a0 = np.zeros(self.nv)
        self.mass_matrix = np.zeros((self.nv, self.nv))
        self.bias = np.zeros(self.nv)
        self.com_m = np.zeros(3)
        self.com_vel_mps = np.zeros(3)
        self.com_jac = np.zeros((3, self.nv))
        self.com_drift = np.zeros(3)
        self.contact_jac_local = np.zeros((12, self.nv))
        """Both soles' 6 x nv Jacobians in their LOCAL frames, stacked (left, right)."""
        self.contact_drift_local = np.zeros(12)
        self.contact_vel_local = np.zeros(12)
        self._lower = np.tril_indices(self.nv, -1)
        self._all = np.arange(self.nv)
        """Every velocity coordinate (the full model's columns for _add_held_load)."""
        """The mass matrix's strict lower triangle (pinocchio fills the upper one)."""
        self.hand_forces_w_n = np.zeros((2, 3))
        """Known forces on the (left, right) hand frames, world axes: what a held object does to
        the hands (its weight share, the squeeze's reaction). update() folds them into `bias`
        (bias - J^T f), so the QP's dynamics, torque limits and foot forces account for them and
        its torques push back."""
        self.hand_moments_w_nm = np.zeros((2, 3))
        """Known moments on the (left, right) hand frames, world axes: a held object's weight acting
        off the hand point (a bottle in one Dex3 hand hangs ~5 cm inside the palm). update() folds them
        into `bias` as bias - J_ang^T m, like hand_forces_w_n."""
        self.hand_masses_kg = np.zeros(2)
        """Point masses moving rigidly with the (left, right) hand frames: a held object's inertia.
        update() adds m J^T J to `mass_matrix` and m J^T (J-dot v) to `bias` (the hand's linear
        Jacobian and drift, world axes), so the hands' force is also -m a_hand: accelerating the
        body accelerates the load (its weight is in hand_forces_w_n, not here)."""
        if self._reduced:
            nr = self.dynamics_model.nv
            self._mr = np.zeros((nr, nr))
            self._mr_lower = np.tril_indices(nr, -1)
            self._m_flat = (self._vi[:, None] * self.nv + self._vi[None, :]).ravel()
            """Where the variant model's mass matrix goes in the flattened 29-DoF one."""
            self._a0r = np.zeros(nr)
            self.mass_matrix[self._locked_v, self._locked_v] = 1.0

    def update(self, q: np.ndarray, v: np.ndarray) -> None:
        """Compute M, bias (C v + g), CoM terms and the soles' contact Jacobians at (q, v)
        (the 29-DoF G1's coordinates; a variant's locked joints are read as locked)."""
        if self._reduced:
            self._update_reduced(q, v)
            return
        pin, m, d = self._pin, self.model, self.data
        pin.computeAllTerms(m, d, q, v)  # M (upper triangle), nle, joint Jacobians, CoM, Jcom
        self.mass_matrix[:] = d.M
        lower = self._lower
        self.mass_matrix[lower] = self.mass_matrix.T[lower]
        self.bias[:] = d.nle
        self.com_m[:] = d.com[0]
        self.com_vel_mps[:] = d.vcom[0]
        self.com_jac[:] = d.Jcom
        # Drift terms: accelerations with zero joint acceleration.
        pin.forwardKinematics(m, d, q, v, self._a0)
        pin.updateFramePlacements(m, d)
        pin.centerOfMass(m, d, pin.KinematicLevel.ACCELERATION)  # on the kinematics just computed (not a third pass)
        self.com_drift[:] = d.acom[0]
        for i, fid in enumerate(self.sole_ids):
            rows = slice(6 * i, 6 * i + 6)
            self.contact_jac_local[rows] = pin.getFrameJacobian(m, d, fid, pin.LOCAL)
            self.contact_drift_local[rows] = pin.getFrameAcceleration(m, d, fid, pin.LOCAL).vector
            self.contact_vel_local[rows] = pin.getFrameVelocity(m, d, fid, pin.LOCAL).vector
        self._add_held_load(m, d, self._all)

    def frame(self, frame_id: int) -> FrameTerms:
        """Kinematics of one frame at the state of the last update()."""
        pin, m, d = self._pin, self.dynamics_model, self.data
        lwa = pin.LOCAL_WORLD_ALIGNED
        placement = d.oMf[frame_id]
        jac = pin.getFrameJacobian(m, d, frame_id, lwa)
        if self._reduced:
            jac = self._columns(jac)
        return FrameTerms(placement.translation.copy(), placement.rotation.copy(), jac,
                          pin.getFrameClassicalAcceleration(m, d, frame_id, lwa).vector,
                          pin.getFrameVelocity(m, d, frame_id, lwa).vector)

    # -- a variant with locked joints ------------------------------------------------------------------
    def _columns(self, jac: np.ndarray) -> np.ndarray:
        """A Jacobian of the variant's model with the 29-DoF G1's columns (0 for locked joints)."""
        out = np.zeros((jac.shape[0], self.nv))
        out[:, self._vi] = jac
        return out

    def _update_reduced(self, q: np.ndarray, v: np.ndarray) -> None:
        # Only the variant's rows and columns are written: the locked coordinates' entries keep what
        # __init__ gave them (unit inertia, zeros) for good.
        pin, m, d, vi = self._pin, self.dynamics_model, self.data, self._vi
        qr, vr = q[self._qi], v[vi]
        pin.computeAllTerms(m, d, qr, vr)
        mr = self._mr
        mr[:] = d.M  # upper triangle
        mr[self._mr_lower] = mr.T[self._mr_lower]
        self.mass_matrix.flat[self._m_flat] = mr.ravel()
        self.bias[vi] = d.nle
        self.com_m[:] = d.com[0]
        self.com_vel_mps[:] = d.vcom[0]
        self.com_jac[:, vi] = d.Jcom
        pin.forwardKinematics(m, d, qr, vr, self._a0r)
        pin.updateFramePlacements(m, d)
        pin.centerOfMass(m, d, pin.KinematicLevel.ACCELERATION)  # on the kinematics just computed
        self.com_drift[:] = d.acom[0]
        for i, fid in enumerate(self.sole_ids):
            rows = slice(6 * i, 6 * i + 6)
            self.contact_jac_local[rows, vi] = pin.getFrameJacobian(m, d, fid, pin.LOCAL)
            self.contact_drift_local[rows] = pin.getFrameAcceleration(m, d, fid, pin.LOCAL).vector
            self.contact_vel_local[rows] = pin.getFrameVelocity(m, d, fid, pin.LOCAL).vector
        self._add_held_load(m, d, vi)

    def _add_held_load(self, m, d, cols: np.ndarray) -> None:
        """The hands' known forces (hand_forces_w_n: bias - J^T f) and point masses (hand_masses_kg:
        m J^T J into the mass matrix, m J^T (J-dot v) into bias) on the 29-DoF coordinates `cols`
        that `m` (the model just computed) has."""
        forces, masses = self.hand_forces_w_n.any(), self.hand_masses_kg.any()
        moments = self.hand_moments_w_nm.any()
        if not (forces or masses or moments):
            return
        pin = self._pin
        full = [pin.getFrameJacobian(m, d, fid, pin.LOCAL_WORLD_ALIGNED) for fid in self.hand_ids]
        jacs = [jac[:3] for jac in full]
        if forces:
            for jac, force in zip(jacs, self.hand_forces_w_n):
                self.bias[cols] -= jac.T @ force
        if moments:
            for jac, moment in zip(full, self.hand_moments_w_nm):
                self.bias[cols] -= jac[3:].T @ moment
        if masses:
            block = np.ix_(cols, cols)
            for fid, jac, mass in zip(self.hand_ids, jacs, self.hand_masses_kg):
                drift = pin.getFrameClassicalAcceleration(m, d, fid, pin.LOCAL_WORLD_ALIGNED).linear
                self.mass_matrix[block] += mass * (jac.T @ jac)
                self.bias[cols] += mass * (jac.T @ drift)
