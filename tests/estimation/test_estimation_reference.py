"""The estimator (written for speed: legs-only model, Python floats) gives what its plain form
gives, the full model and numpy arrays throughout (kept here as the reference), on the states of a
walk and on perturbed ones."""

import copy

import numpy as np
import pinocchio as pin

from g1_control.estimation.estimator import GRAVITY_W, SOLE_OFFSET_M, EstimatorConfig, StateEstimator
from g1_control.launch.builder import build_loop, make_sim_backend
from g1_control.launch.schema import LaunchFile, Segment
from g1_control.robot import description, g1
from g1_control.rotations import quat_to_rot, yaw_of
from g1_control.types import EstimatedState


class ReferenceEstimator:
    def __init__(self, config=None):
        self.config = config or EstimatorConfig()
        self.model = pin.Model(description.pinocchio_model())
        self.soles = []
        for body in g1.FOOT_BODIES:
            parent = self.model.getFrameId(body)
            frame = self.model.frames[parent]
            placement = frame.placement * pin.SE3(np.eye(3), SOLE_OFFSET_M)
            self.soles.append(self.model.addFrame(pin.Frame(body + "_sole", frame.parentJoint, parent, placement,
                                                            pin.FrameType.OP_FRAME)))
        self.data = self.model.createData()
        self.estimate = EstimatedState()
        self.last_t = None

    def update(self, state):
        est = self.estimate
        quat = state.imu_quat_wxyz
        rot = quat_to_rot(quat)
        q, v = np.zeros(self.model.nq), np.zeros(self.model.nv)
        q[3:7] = (quat[1], quat[2], quat[3], quat[0])
        q[7:] = state.q_rad
        v[3:6] = state.imu_gyro_radps
        v[6:] = state.dq_radps
        pin.forwardKinematics(self.model, self.data, q, v)
        heights, velocities = np.zeros(2), np.zeros((2, 3))
        for i, fid in enumerate(self.soles):
            heights[i] = pin.updateFramePlacement(self.model, self.data, fid).translation[2]
            velocities[i] = pin.getFrameVelocity(self.model, self.data, fid, pin.LOCAL_WORLD_ALIGNED).linear
        d = (heights[1] - heights[0]) / self.config.stance_height_scale_m
        w_left = 1.0 / (1.0 + np.exp(-np.clip(d, -50, 50)))
        weights = np.array([w_left, 1.0 - w_left])
        v_kin = -(weights @ velocities)
        dt = 0.0 if self.last_t is None else max(0.0, state.t_s - self.last_t)
        self.last_t = state.t_s
        if dt == 0.0:
            est.base_linvel_w_mps = v_kin
        else:
            predicted = est.base_linvel_w_mps + (rot @ state.imu_acc_mps2 + GRAVITY_W) * dt
            gain = dt / (self.config.kinematic_gain_tau_s + dt)
            est.base_linvel_w_mps = predicted + gain * (v_kin - predicted)
        est.t_s = state.t_s
        est.base_quat_wxyz = quat.copy()
        est.base_angvel_b_radps = state.imu_gyro_radps.copy()
        est.stance_weight = weights
        yaw = est.yaw_rad = yaw_of(quat)
        c, s = np.cos(yaw), np.sin(yaw)
        lin = est.base_linvel_w_mps
        est.heading_velocity = np.array([c * lin[0] + s * lin[1], -s * lin[0] + c * lin[1],
                                         (rot @ state.imu_gyro_radps)[2]])
        return est


def _walk_states():
    launch = LaunchFile(name="estimator_states")
    launch.input.timeline = [Segment(0.3, label="stand"), Segment(1.2, vx_mps=0.5, wz_radps=0.4, label="walk")]
    launch.output.video = "off"
    loop = build_loop(launch, backend=make_sim_backend(launch))
    loop.reset()
    states = []
    update = loop.estimator.update
    loop.estimator.update = lambda state: (states.append(copy.deepcopy(state)), update(state))[1]
    loop.run(1.5)
    return states


def test_estimates_equal_the_reference_on_walk_and_perturbed_states():
    states = _walk_states()
    rng = np.random.default_rng(3)
    for state in states[::3]:  # tilted, spinning, both feet in the air: off the walk's beaten path
        s = copy.deepcopy(state)
        quat = s.imu_quat_wxyz + rng.normal(scale=0.2, size=4)
        s.imu_quat_wxyz = quat / np.linalg.norm(quat)
        s.q_rad = s.q_rad + rng.normal(scale=0.3, size=g1.NUM_JOINTS)
        s.dq_radps = rng.normal(scale=4.0, size=g1.NUM_JOINTS)
        s.imu_gyro_radps = rng.normal(scale=2.0, size=3)
        states.append(s)
    fast, ref = StateEstimator(), ReferenceEstimator()
    stance_seen = set()
    for state in states:
        a, b = fast.update(state), ref.update(state)
        for name in ("base_linvel_w_mps", "heading_velocity", "stance_weight", "base_quat_wxyz", "base_angvel_b_radps"):
            np.testing.assert_allclose(getattr(a, name), getattr(b, name), rtol=0, atol=1e-12, err_msg=name)
        assert a.yaw_rad == b.yaw_rad and a.t_s == b.t_s
        stance_seen.add(int(np.argmax(b.stance_weight)))
    assert stance_seen == {0, 1}  # both feet carried the weight at some point
