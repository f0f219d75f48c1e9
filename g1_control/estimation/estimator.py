"""Base state estimation from what the robot reports, identical on the simulator and the robot.

Orientation and angular velocity come from the IMU. Linear velocity comes from leg kinematics:
a foot in stance does not move, so the base moves at minus the stance foot's velocity relative
to the base (pinocchio, joint velocities and gyro). The accelerometer propagates the estimate
between kinematic corrections (a complementary filter), which smooths the switch between feet.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from g1_control.robot import description, g1
from g1_control.rotations import quat_to_rot_rows, yaw_of
from g1_control.types import EstimatedState, RobotState

GRAVITY_W = np.array([0.0, 0.0, -9.81])
SOLE_OFFSET_M = np.array([0.035, 0.0, -0.035])
"""Sole centre in the ankle-roll link frame (middle of the URDF's four foot contact spheres)."""


@dataclass
class EstimatorConfig:
    kinematic_gain_tau_s: float = 0.1
    """Time constant pulling the integrated velocity to the kinematic one."""
    max_predict_s: float = 0.05
    """Longer between two states (a stalled loop), the velocity is the kinematic one: one accelerometer
    sample times a stall's length is not the velocity change over it (a landing foot's impact read at
    the stall's end turns into metres per second)."""
    stance_height_scale_m: float = 0.003
    """Soft stance weighting: the foot lower by this much gets 73 % of the weight; sharp, because blending in the swing foot biases the speed low."""


class StateEstimator:
    def __init__(self, config: EstimatorConfig | None = None):
        import pinocchio as pin

        self._pin = pin
        self.config = config or EstimatorConfig()
        # Only the legs matter (base -> sole chains): the other joints are locked out of the model,
        # which leaves the legs' kinematics as they are and halves the forward kinematics.
        full = description.pinocchio_model()
        keep: set[int] = set()
        for body in g1.FOOT_BODIES:
            joint = full.frames[full.getFrameId(body)].parentJoint
            while joint > 0:
                keep.add(joint)
                joint = full.parents[joint]
        locked = [j for j in range(1, full.njoints) if j not in keep]
        self.model = pin.buildReducedModel(full, locked, pin.neutral(full))
        self._n_legs = self.model.nq - 7
        names = tuple(self.model.names[2:])  # after "universe" and the floating base
        if names != g1.JOINT_NAMES[: self._n_legs]:
            raise ValueError(f"estimator: leg joints {names} are not the robot's first joints in order")
        self._soles = []
        for body in g1.FOOT_BODIES:
            parent = self.model.getFrameId(body)
            frame = self.model.frames[parent]
            placement = frame.placement * pin.SE3(np.eye(3), SOLE_OFFSET_M)
            self._soles.append(self.model.addFrame(
                pin.Frame(body.replace("ankle_roll_link", "sole"), frame.parentJoint, parent, placement,
                          pin.FrameType.OP_FRAME)))
        self.data = self.model.createData()
        self._q = np.zeros(self.model.nq)
        self._v = np.zeros(self.model.nv)
        self.estimate = EstimatedState()
        self._last_t: float | None = None

    def reset(self, state: RobotState | None = None) -> None:
        self.estimate = EstimatedState()
        self._last_t = None

    def sole_offsets_w_m(self) -> np.ndarray:
        """(2, 3) left and right sole centres minus the base position, world axes (the IMU's
        orientation), as the last update() computed them."""
        return np.array([self.data.oMf[f].translation for f in self._soles])

    def update(self, state: RobotState, contacts: np.ndarray | None = None) -> EstimatedState:
        """contacts: (left, right) feet known to be in stance (a controller's contact schedule);
        None: the lower foot is taken as the stance foot. Known contacts matter on uneven ground:
        a foot swinging up from the floor next to one standing on a step is the lower one."""
        # Small vectors are handled as Python floats: this runs at 100 Hz and numpy's per-call cost
        # dominates 3-vector arithmetic.
        pin, model, data = self._pin, self.model, self.data
        est = self.estimate
        quat = state.imu_quat_wxyz
        w, x, y, z = quat.tolist()
        # Base at the origin with the IMU's orientation and zero linear velocity: foot velocities
        # are then relative to the base, expressed in world axes.
        q, v = self._q, self._v
        q[3:7] = (x, y, z, w)
        n = self._n_legs
        q[7:] = state.q_rad[:n]
        v[3:6] = state.imu_gyro_radps
        v[6:] = state.dq_radps[:n]
        pin.forwardKinematics(model, data, q, v)
        left, right = self._soles
        height_left = pin.updateFramePlacement(model, data, left).translation[2]
        height_right = pin.updateFramePlacement(model, data, right).translation[2]
        vel_left = pin.getFrameVelocity(model, data, left, pin.LOCAL_WORLD_ALIGNED).linear.tolist()
        vel_right = pin.getFrameVelocity(model, data, right, pin.LOCAL_WORLD_ALIGNED).linear.tolist()
        if contacts is not None and (contacts[0] or contacts[1]):
            w_left = float(bool(contacts[0])) / (float(bool(contacts[0])) + float(bool(contacts[1])))
        else:
            # Soft stance: the lower foot carries the weight.
            d = float(height_right - height_left) / self.config.stance_height_scale_m
            w_left = 1.0 / (1.0 + math.exp(-min(50.0, max(-50.0, d))))
        w_right = 1.0 - w_left
        v_kin = [-(w_left * a + w_right * b) for a, b in zip(vel_left, vel_right)]

        rot = quat_to_rot_rows(quat)
        dt = 0.0 if self._last_t is None else max(0.0, state.t_s - self._last_t)
        self._last_t = state.t_s
        if dt == 0.0 or dt > self.config.max_predict_s:
            linvel = v_kin
        else:
            acc = state.imu_acc_mps2.tolist()
            acc_w = [r[0] * acc[0] + r[1] * acc[1] + r[2] * acc[2] + g for r, g in zip(rot, GRAVITY_W.tolist())]
            gain = dt / (self.config.kinematic_gain_tau_s + dt)
            predicted = [p + a * dt for p, a in zip(est.base_linvel_w_mps.tolist(), acc_w)]
            linvel = [p + gain * (k - p) for p, k in zip(predicted, v_kin)]
        est.base_linvel_w_mps = np.array(linvel)
        est.t_s = state.t_s
        est.base_quat_wxyz = quat.copy()
        est.base_angvel_b_radps = state.imu_gyro_radps.copy()
        est.stance_weight = np.array((w_left, w_right))
        est.pelvis_height_m = -float(min(height_left, height_right))
        yaw = est.yaw_rad = yaw_of(quat)
        c, s = math.cos(yaw), math.sin(yaw)
        vx, vy, _ = linvel
        gx, gy, gz = state.imu_gyro_radps.tolist()
        r2 = rot[2]
        est.heading_velocity = np.array((c * vx + s * vy, -s * vx + c * vy, r2[0] * gx + r2[1] * gy + r2[2] * gz))
        return est
