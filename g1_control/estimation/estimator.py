"""Base state estimation from what the robot reports, identical on the simulator and the robot.

Orientation and angular velocity come from the IMU. Linear velocity comes from leg kinematics:
a foot in stance does not move, so the base moves at minus the stance foot's velocity relative
to the base (pinocchio, joint velocities and gyro). The accelerometer propagates the estimate
between kinematic corrections (a complementary filter), which smooths the switch between feet.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from g1_control.robot import description, g1
from g1_control.rotations import quat_to_rot, yaw_of
from g1_control.types import EstimatedState, RobotState

GRAVITY_W = np.array([0.0, 0.0, -9.81])
SOLE_OFFSET_M = np.array([0.035, 0.0, -0.035])
"""Sole centre in the ankle-roll link frame (middle of the URDF's four foot contact spheres)."""






@dataclass
class EstimatorConfig:
    kinematic_gain_tau_s: float = 0.1
    """Time constant pulling the integrated velocity to the kinematic one."""
    stance_height_scale_m: float = 0.003
    """Soft stance weighting: the foot lower by this much gets 73 % of the weight; sharp, because blending in the swing foot biases the speed low."""


class StateEstimator:
    def __init__(self, config: EstimatorConfig | None = None):
        import pinocchio as pin

        self._pin = pin
        self.config = config or EstimatorConfig()
        self.model = pin.Model(description.pinocchio_model())
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

    def update(self, state: RobotState, contacts: np.ndarray | None = None) -> EstimatedState:
        """contacts: (left, right) feet known to be in stance (a controller's contact schedule);
        None: the lower foot is taken as the stance foot. Known contacts matter on uneven ground:
        a foot swinging up from the floor next to one standing on a step is the lower one."""
        pin = self._pin
        est = self.estimate
        quat = state.imu_quat_wxyz
        rot = quat_to_rot(quat)
        # Base at the origin with the IMU's orientation and zero linear velocity: foot velocities
        # are then relative to the base, expressed in world axes.
        self._q[3:7] = (quat[1], quat[2], quat[3], quat[0])
        self._q[7:] = state.q_rad
        self._v[3:6] = state.imu_gyro_radps
        self._v[6:] = state.dq_radps
        pin.forwardKinematics(self.model, self.data, self._q, self._v)
        heights, velocities = np.zeros(2), np.zeros((2, 3))
        for i, fid in enumerate(self._soles):
            heights[i] = pin.updateFramePlacement(self.model, self.data, fid).translation[2]
            velocities[i] = pin.getFrameVelocity(self.model, self.data, fid, pin.LOCAL_WORLD_ALIGNED).linear
        if contacts is not None and np.any(contacts):
            weights = np.asarray(contacts, dtype=float) / float(np.sum(contacts))
        else:
            # Soft stance: the lower foot carries the weight.
            d = (heights[1] - heights[0]) / self.config.stance_height_scale_m
            w_left = 1.0 / (1.0 + np.exp(-np.clip(d, -50, 50)))
            weights = np.array([w_left, 1.0 - w_left])
        v_kin = -(weights @ velocities)

        dt = 0.0 if self._last_t is None else max(0.0, state.t_s - self._last_t)
        self._last_t = state.t_s
        if dt == 0.0:
            est.base_linvel_w_mps = v_kin
        else:
            acc_w = rot @ state.imu_acc_mps2 + GRAVITY_W
            predicted = est.base_linvel_w_mps + acc_w * dt
            gain = dt / (self.config.kinematic_gain_tau_s + dt)
            est.base_linvel_w_mps = predicted + gain * (v_kin - predicted)
        est.t_s = state.t_s
        est.base_quat_wxyz = quat.copy()
        est.base_angvel_b_radps = state.imu_gyro_radps.copy()
        est.stance_weight = weights
        est.pelvis_height_m = -float(min(heights[0], heights[1]))
        yaw = est.yaw_rad = yaw_of(quat)
        c, s = np.cos(yaw), np.sin(yaw)
        v = est.base_linvel_w_mps
        est.heading_velocity = np.array([c * v[0] + s * v[1], -s * v[0] + c * v[1], (rot @ state.imu_gyro_radps)[2]])
        return est
