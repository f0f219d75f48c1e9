"""The G1's rigid-body dynamics for the controller: pinocchio model with the motors' armature,
the frames the controller uses (soles, pelvis, torso, hands) and, per tick, everything the QP
needs: mass matrix, bias forces, frame Jacobians and their drift terms (J_dot v).

Configuration and velocity are pinocchio's: q = (x y z, qx qy qz qw, joints), v = (base linear
velocity in the base frame, base angular velocity in the base frame, joint velocities).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from g1_control.robot import description, g1

SOLE_OFFSET_M = np.array([0.035, 0.0, -0.035])
"""Sole frame origin in the ankle-roll link: midway between the URDF's front (x 0.12) and rear
(x -0.05) contact spheres, on the plane their bottoms touch (centres z -0.03, radius 0.005)."""

SOLE_FRAMES = ("left_sole", "right_sole")
HAND_FRAMES = ("left_hand", "right_hand")
HAND_OFFSET_M = np.array([0.1, 0.0, 0.0])
"""Hand point in the wrist-yaw link: roughly the palm centre (the URDF's rubber hand extends ~0.1 m)."""


def build_model():
    """pinocchio Model of the G1 with armature and the controller's extra frames."""
    import pinocchio as pin

    model = pin.Model(description.pinocchio_model())
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


class WbcModel:
    """Evaluates the dynamics terms the QP needs at one state; reuses its buffers."""

    def __init__(self) -> None:
        import pinocchio as pin

        self._pin = pin
        self.model = build_model()
        self.data = self.model.createData()
        self.nv = self.model.nv
        self.nq = self.model.nq
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
        self.hand_forces_w_n = np.zeros((2, 3))
        """Known forces on the (left, right) hand frames, world axes: what a held object does to
        the hands (its weight share, the squeeze's reaction). update() folds them into `bias`
        (bias - J^T f), so the QP's dynamics, torque limits and foot forces account for them and
        its torques push back."""

    def update(self, q: np.ndarray, v: np.ndarray) -> None:
        """Compute M, bias (C v + g), CoM terms and the soles' contact Jacobians at (q, v)."""
        pin, m, d = self._pin, self.model, self.data
        pin.computeAllTerms(m, d, q, v)  # M (upper triangle), nle, joint Jacobians, CoM, Jcom
        self.mass_matrix[:] = d.M
        lower = np.tril_indices(self.nv, -1)
        self.mass_matrix[lower] = self.mass_matrix.T[lower]
        self.bias[:] = d.nle
        self.com_m[:] = d.com[0]
        self.com_vel_mps[:] = d.vcom[0]
        self.com_jac[:] = d.Jcom
        # Drift terms: accelerations with zero joint acceleration.
        pin.forwardKinematics(m, d, q, v, self._a0)
        pin.updateFramePlacements(m, d)
        pin.centerOfMass(m, d, q, v, self._a0)
        self.com_drift[:] = d.acom[0]
        for i, fid in enumerate(self.sole_ids):
            rows = slice(6 * i, 6 * i + 6)
            self.contact_jac_local[rows] = pin.getFrameJacobian(m, d, fid, pin.LOCAL)
            self.contact_drift_local[rows] = pin.getFrameAcceleration(m, d, fid, pin.LOCAL).vector
            self.contact_vel_local[rows] = pin.getFrameVelocity(m, d, fid, pin.LOCAL).vector
        if self.hand_forces_w_n.any():
            for fid, force in zip(self.hand_ids, self.hand_forces_w_n):
                self.bias -= pin.getFrameJacobian(m, d, fid, pin.LOCAL_WORLD_ALIGNED)[:3].T @ force

    def frame(self, frame_id: int) -> FrameTerms:
        """Kinematics of one frame at the state of the last update()."""
        pin, m, d = self._pin, self.model, self.data
        lwa = pin.LOCAL_WORLD_ALIGNED
        placement = d.oMf[frame_id]
        return FrameTerms(placement.translation.copy(), placement.rotation.copy(),
                          pin.getFrameJacobian(m, d, frame_id, lwa),
                          pin.getFrameClassicalAcceleration(m, d, frame_id, lwa).vector,
                          pin.getFrameVelocity(m, d, frame_id, lwa).vector)
