"""The simulated Dex3-1 fingers (backend.hands: dex3): their motors under the hand's motor law, the
hand link the safety layer drives them through, and the loop's hands stage (a bottle picked with them:
tests/tools/test_bench_bottle.py)."""

from __future__ import annotations

import numpy as np
import pytest

from g1_control.errors import RobotDescriptionError
from g1_control.robot import dex3
from g1_control.sim.mujoco_backend import MujocoBackend, MujocoConfig
from g1_control.types import FingerCommand, KinematicReference


@pytest.fixture(scope="module")
def backend():
    b = MujocoBackend(MujocoConfig(hands="dex3"))
    yield b
    b.close()


def _command(side: str, q: np.ndarray, kp: float = 2.0, kd: float = 0.05, tau: float = 0.0) -> FingerCommand:
    n = dex3.NUM_MOTORS
    return FingerCommand(q_rad=np.asarray(q, dtype=float), kp=np.full(n, kp), kd=np.full(n, kd), tau_nm=np.full(n, tau))


def test_the_finger_motors_follow_the_hands_motor_law_and_reset_to_the_open_pose(backend):
    backend.reset()
    lim = dex3.hand_limits("right")
    goal = 0.6 * lim.closed_rad  # halfway-plus to closed, inside the range
    backend.write_fingers("right", _command("right", goal, kp=3.0, kd=0.05))
    backend.step(1.0)
    st = backend.read_fingers("right")
    closing = lim.closing_sign != 0
    assert np.abs(st.q_rad - goal)[closing].max() < 0.05, st.q_rad
    assert st.t_s == pytest.approx(backend.time_s)
    # pressed against its closed stop by a target 0.4 rad beyond it: the torque is the law's, kp (q* - q) + tau_ff,
    # and a law past the motor's effort is clipped to it
    past = lim.closed_rad + 0.4 * lim.closing_sign
    backend.write_fingers("right", _command("right", past, kp=2.0, kd=0.05, tau=0.1))
    backend.step(0.5)
    st = backend.read_fingers("right")
    law = 2.0 * (past - st.q_rad) + 0.1 - 0.05 * st.dq_radps
    assert np.allclose(st.tau_nm[closing], law[closing], atol=2e-3), (st.tau_nm, law)
    assert np.all(np.abs(st.tau_nm[closing]) > 0.3)
    backend.write_fingers("right", _command("right", past, kp=2.0, tau=3.0))
    backend.step(0.2)
    plus = lim.closing_sign > 0  # the fingers the +3 N m feed-forward presses closed
    assert np.allclose(backend.read_fingers("right").tau_nm[plus], lim.effort_nm[plus], atol=1e-6), "clipped"
    left = backend.read_fingers("left")
    assert np.abs(left.q_rad).max() < 0.2, "the other hand still holds the open pose"
    backend.reset()
    backend.step(0.5)
    assert np.abs(backend.read_fingers("right").q_rad).max() < 0.2, "reset() brings back the open-pose law"


def test_a_disabled_finger_motor_gives_no_torque_and_a_nan_command_is_refused_unapplied(backend):
    backend.reset()
    cmd = _command("right", dex3.hand_limits("right").closed_rad, kp=3.0)
    cmd.enable[:] = False
    backend.write_fingers("right", cmd)
    backend.step(0.05)
    assert np.all(backend.read_fingers("right").tau_nm == 0.0)
    assert not backend.read_fingers("right").motor_enabled.any()
    before = backend.model.actuator_biasprm.copy()
    bad = _command("right", np.zeros(dex3.NUM_MOTORS))
    bad.q_rad[2] = np.nan
    with pytest.raises(ValueError, match="right hand command is not finite"):
        backend.write_fingers("right", bad)
    assert np.array_equal(backend.model.actuator_biasprm, before)


def test_a_robot_without_hands_has_no_fingers_to_command_and_says_so():
    b = MujocoBackend(MujocoConfig())
    assert b.hand_sides == ()
    with pytest.raises(RobotDescriptionError, match="no Dex3 hands .*backend.hands is 'none'"):
        b.read_fingers("left")
    from g1_control.sim.mujoco_hands import MujocoHandLink

    with pytest.raises(RobotDescriptionError, match="no Dex3 hands"):
        MujocoHandLink(b)


def _stage(backend):
    from g1_control.safety.hands import GuardedHands
    from g1_control.sim.mujoco_hands import MujocoHandLink
    from g1_control.trackers.hands import HandsStage

    return HandsStage(GuardedHands(MujocoHandLink(backend), clock=lambda: backend.time_s))


def test_the_hands_stage_damps_the_fingers_when_the_body_is_damped(backend):
    backend.reset()
    stage = _stage(backend)
    ref = KinematicReference()
    ref.grasp_nm[1] = 0.5
    stage.update(ref, backend.time_s, body_faulted=False)
    assert stage.tripped is None and stage.grasps["right"] is not None
    acts = np.array([backend.model.actuator(n.removesuffix("_joint")).id for n in dex3.joint_names("right")])
    assert np.all(backend.model.actuator_biasprm[acts, 1] < 0), "a grasp holds the fingers stiff"
    stage.update(ref, backend.time_s + 0.004, body_faulted=True)
    assert stage.tripped is not None and "body's safety layer" in stage.tripped
    for side in dex3.SIDES:
        acts = np.array([backend.model.actuator(n.removesuffix("_joint")).id for n in dex3.joint_names(side)])
        assert np.all(backend.model.actuator_biasprm[acts, 1] == 0.0), "no stiffness: damping only"
        assert np.all(backend.model.actuator_biasprm[acts, 2] == -dex3.DAMPING_KD)
    # latched: the next ticks, the body fine again, still damp until reset
    stage.update(ref, backend.time_s + 0.008, body_faulted=False)
    assert np.all(backend.model.actuator_biasprm[acts, 1] == 0.0)
    stage.reset()
    stage.update(KinematicReference(), backend.time_s + 0.012, body_faulted=False)
    assert stage.tripped is None and np.all(backend.model.actuator_biasprm[acts, 1] < 0)


def test_a_nan_finger_angle_in_the_reference_trips_the_hands_and_damps_them(backend):
    backend.reset()
    stage = _stage(backend)
    ref = KinematicReference()
    ref.hand_q_rad = np.zeros(14)
    stage.update(ref, backend.time_s, body_faulted=False)
    assert stage.tripped is None
    ref.hand_q_rad[3] = np.nan
    stage.update(ref, backend.time_s + 0.004, body_faulted=False)
    assert stage.tripped is not None and "not finite" in stage.tripped
    acts = np.array([backend.model.actuator(n.removesuffix("_joint")).id for n in dex3.joint_names("left")])
    assert np.all(backend.model.actuator_biasprm[acts, 1] == 0.0)


def test_the_hands_stage_sends_the_plans_finger_angles_by_name():
    """hand_q_rad is in the generator's FINGER_JOINTS order (index before middle); each motor gets its own."""
    from g1_control.generator.skeleton import FINGER_JOINTS

    b = MujocoBackend(MujocoConfig(hands="dex3"))
    b.reset()
    stage = _stage(b)
    ref = KinematicReference()
    ref.hand_q_rad = np.zeros(14)
    ref.hand_q_rad[FINGER_JOINTS.index("right_hand_index_0_joint")] = 0.5
    stage.update(ref, 0.0, body_faulted=False)
    b.step(1.0)
    for _ in range(100):  # the safety layer ramps the target at its speed limit: feed it on
        stage.update(ref, b.time_s, body_faulted=False)
        b.step(0.01)
    q = b.read_fingers("right").q_rad
    assert q[dex3.FINGERS.index("index_0")] > 0.35 and abs(q[dex3.FINGERS.index("middle_0")]) < 0.1, q
    b.close()


def test_a_grasp_asked_past_the_motors_effort_damps_the_fingers_with_the_reason(backend):
    backend.reset()
    stage = _stage(backend)
    ref = KinematicReference()
    ref.grasp_nm[0] = 2.0  # a finger motor gives 1.4 N m
    stage.update(ref, backend.time_s, body_faulted=False)
    assert stage.tripped is not None and "left hand: the plan's grasp is refused: torque_limit_nm" in stage.tripped
    acts = np.array([backend.model.actuator(n.removesuffix("_joint")).id for n in dex3.joint_names("left")])
    assert np.all(backend.model.actuator_biasprm[acts, 1] == 0.0)
