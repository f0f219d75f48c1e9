"""The styled-walking pieces of the policy tracker (g1_control/trackers/styled.py), each checked on
a case whose answer is known by hand or by an independent computation (MuJoCo, finite differences)."""

import mujoco
import numpy as np
import pinocchio as pin
import pytest

from g1_control.generator.styles import ROLLOUT_STYLES
from g1_control.robot import description, g1
from g1_control.trackers.locomotion import LocomotionPolicyTracker, VelocityCorrectionConfig, VelocityCorrector
from g1_control.trackers.policy_spec import load_spec
from g1_control.trackers.styled import ARMS, CROUCH_DIRECTION, ComBalance, Crouch, PlanInverseDynamics
from g1_control.types import EstimatedState, JointReference, RobotState


@pytest.fixture(scope="module")
def spec():
    return load_spec("holosoma_loco_ppo")


def test_plan_inverse_dynamics_equals_mujoco_inverse_dynamics():
    model = description.mujoco_spec(timestep_s=0.002).compile()
    data = mujoco.MjData(model)
    dyn = PlanInverseDynamics()
    rng = np.random.default_rng(3)
    for _ in range(3):
        q = np.clip(g1.DEFAULT_Q_RAD + rng.normal(0, 0.3, 29), g1.Q_MIN_RAD, g1.Q_MAX_RAD)
        dq, ddq = rng.normal(0, 1.0, 29), rng.normal(0, 5.0, 29)
        quat = rng.normal(size=4)
        quat /= np.linalg.norm(quat)
        data.qpos[3:7], data.qpos[7:], data.qvel[:] = quat, q, 0.0
        data.qvel[6:], data.qacc[:] = dq, 0.0
        data.qacc[6:] = ddq
        mujoco.mj_inverse(model, data)
        dyn.joint_q[:], dyn.joint_v[:], dyn.joint_a[:] = q, dq, ddq
        np.testing.assert_allclose(dyn(quat)[6:], data.qfrc_inverse[6:], atol=1e-8)


def test_com_balance_takes_back_the_asked_fraction_of_the_shift():
    model = description.pinocchio_model()
    data = model.createData()

    def com(joints):
        q = np.zeros(model.nq)
        q[6] = 1.0
        q[7:] = joints
        return pin.centerOfMass(model, data, q).copy()

    base = com(g1.DEFAULT_Q_RAD)
    balance = ComBalance(g1.DEFAULT_Q_RAD, fraction=1.0, max_rad=1.0)
    balance.update(g1.DEFAULT_Q_RAD)
    assert balance.pitch_rad == pytest.approx(0.0, abs=1e-9) and balance.roll_rad == pytest.approx(0.0, abs=1e-9)
    plan = ROLLOUT_STYLES["wave"].pose(0.2)  # one arm up: the centre of mass moves forward and sideways
    shift = com(plan) - base
    assert abs(shift[0]) > 0.01 and abs(shift[1]) > 0.001
    balance.update(plan)
    leaned = plan.copy()
    leaned[g1.JOINT_INDEX["waist_pitch_joint"]] += balance.pitch_rad
    leaned[g1.JOINT_INDEX["waist_roll_joint"]] += balance.roll_rad
    residual = com(leaned) - base
    assert abs(residual[0]) < 0.1 * abs(shift[0]) and abs(residual[1]) < 0.2 * abs(shift[1])
    half = ComBalance(g1.DEFAULT_Q_RAD, fraction=0.5, max_rad=1.0)
    half.update(plan)
    assert half.pitch_rad == pytest.approx(0.5 * balance.pitch_rad)


def test_policy_sees_its_trained_upper_body_while_the_motors_follow_the_plan(spec):
    tracker = LocomotionPolicyTracker(spec)
    state = RobotState(q_rad=g1.DEFAULT_Q_RAD.copy())
    state.q_rad[16] += 0.7  # an arm far from the default pose
    state.dq_radps[16] = 2.0
    tracker.reset(state)
    ref = JointReference(q_rad=ROLLOUT_STYLES["carry"].pose(0.0), upper_body_override=True)
    ref.q_rad[g1.JOINT_INDEX["waist_yaw_joint"]] = 0.3
    out = tracker.act(ref, state)
    dof_pos, dof_vel = tracker._dof_pos, tracker._dof_vel
    assert np.all(dof_pos[ARMS] == 0.0) and np.all(dof_vel[ARMS] == 0.0)
    assert dof_pos[12] == pytest.approx(-0.3)  # waist yaw seen where the policy keeps it
    lean = tracker.upper_body.waist_offset
    assert lean[2] < -0.05  # carry holds the arms forward: the torso leans back
    assert dof_pos[14] == pytest.approx(-lean[2])
    np.testing.assert_array_equal(out.q_rad[ARMS], ref.q_rad[ARMS])
    assert np.all(out.tau_nm[:15] == 0.0) and np.any(out.tau_nm[ARMS] != 0.0)
    # the next tick's arm velocity target is the plan's finite difference
    ref2 = JointReference(q_rad=ref.q_rad.copy(), upper_body_override=True)
    ref2.q_rad[15] += 0.01
    out = tracker.act(ref2, state)
    assert out.dq_radps[15] == pytest.approx(0.01 / 0.02)
    # handed back: the policy sees and drives its own arms again
    out = tracker.act(JointReference(q_rad=g1.DEFAULT_Q_RAD.copy()), state)
    assert tracker._dof_pos[16] == pytest.approx(0.7) and np.all(out.tau_nm == 0.0)


def test_crouch_reaches_the_height_and_moves_smoothly():
    crouch = Crouch(g1.DEFAULT_Q_RAD, 0.02)
    crouch.update(None, 0.75)
    assert np.all(crouch.offset == 0.0)
    crouch.update(0.65, 0.75)
    assert 0.0 < crouch.angle_rad <= 0.5 * 0.02 + 1e-12  # rate-limited
    np.testing.assert_allclose(crouch.offset, CROUCH_DIRECTION * crouch.angle_rad)
    for _ in range(100):
        crouch.update(0.68, None)  # kinematics alone: 7.7 cm below the straight legs' 0.757 m
    a_ff = crouch.angle_rad
    assert 0.2 < a_ff < 0.32
    for _ in range(200):
        crouch.update(0.68, 0.71)  # the robot stands 3 cm too high: bend further
    assert crouch.angle_rad > a_ff
    for _ in range(2000):
        crouch.update(0.40, 0.60)  # asked beyond reach: held at the deepest crouch
    assert crouch.angle_rad == pytest.approx(crouch.max_rad)
    for _ in range(100):
        crouch.update(None, 0.6)
    assert crouch.angle_rad == 0.0


def test_correction_waits_to_settle_and_holds_uncommanded_axes_at_zero():
    corr = VelocityCorrector(VelocityCorrectionConfig(settle_s=1.0), dt_s=0.02)
    cmd = np.array([0.0, 0.2, 0.0])
    drifting = np.array([0.2, 0.1, 0.0])  # moving forward while asked to go sideways only
    for _ in range(49):
        corr(cmd, drifting)
    assert np.all(corr.integral == 0.0)
    for _ in range(100):
        out = corr(cmd, drifting)
    assert corr.integral[1] > 0.0 and out[1] > 0.2  # too slow sideways: ask for more
    assert corr.integral[0] < 0.0 and out[0] < 0.0  # drifting forward: ask to go back
    assert np.all(corr(np.zeros(3), drifting) == 0.0) and np.all(corr.integral == 0.0)  # standing resets


def test_command_limits_come_from_the_measured_envelope(spec):
    assert spec.envelope is not None, "the shipped spec has no measured envelope (g1 bench envelope --write)"
    limits = LocomotionPolicyTracker(spec).command_limits
    trained = LocomotionPolicyTracker(spec, envelope_limits=False).command_limits
    assert limits == spec.envelope.command_limits and trained == spec.command_limits
    assert limits.vx_mps[1] < trained.vx_mps[1] and limits.vy_mps[1] < trained.vy_mps[1]


def test_observe_keeps_the_estimators_height(spec):
    tracker = LocomotionPolicyTracker(spec)
    tracker.observe(EstimatedState(pelvis_height_m=0.7))
    assert tracker.height_estimate == 0.7
