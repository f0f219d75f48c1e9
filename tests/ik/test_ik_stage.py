"""IKStage: a feasible plan passes through untouched; any other reference is solved by the IK, with
what the IK does not solve (upper-body override, pelvis height, phase) carried along."""

import numpy as np
import pytest

from g1_control.generator.scripted import TrajectoryGenerator, build_reference
from g1_control.generator.velocity import VelocityReferenceGenerator
from g1_control.ik.retargeter import IKConfig, IKRetargeter
from g1_control.ik.stage import IKStage
from g1_control.interfaces import Retargeter
from g1_control.robot import g1
from g1_control.types import PHASE_WHOLE_BODY, Command, JointReference, KinematicReference, RobotState


@pytest.fixture(scope="module")
def stage():
    return IKStage(IKConfig(hold_contacts=False, com_cost=(0.0, 0.0, 0.0)))


def _standing_reference() -> KinematicReference:
    ref = KinematicReference(q_rad=g1.DEFAULT_Q_RAD.copy())
    ref.root_pos_w_m[2] = g1.DEFAULT_PELVIS_HEIGHT_M
    return ref


def test_a_feasible_plan_is_passed_on_as_it_is_and_nothing_is_solved(stage):
    plan = JointReference(q_rad=np.full(g1.NUM_JOINTS, 5.0), dq_radps=np.ones(g1.NUM_JOINTS), phase=PHASE_WHOLE_BODY)
    plan.hand_forces_w_n[:] = 3.0
    # q_rad far outside the joint limits: the IK would change it; a feasible plan is not its business
    ref = KinematicReference(q_rad=np.full(g1.NUM_JOINTS, 5.0), feasible_plan=plan)
    before = stage.solved_ticks
    out = stage.solve(ref, g1.DEFAULT_Q_RAD)
    assert out is plan and np.all(out.q_rad == 5.0) and np.all(out.hand_forces_w_n == 3.0)
    assert stage.solved_ticks == before


def test_a_reference_without_a_plan_is_solved_within_the_limits(stage):
    assert isinstance(stage, Retargeter)
    ref = _standing_reference()
    ref.q_rad[g1.JOINT_INDEX["left_knee_joint"]] = 5.0  # beyond the knee's 2.88 rad limit
    ref.upper_body_override, ref.pelvis_height_m, ref.phase = True, 0.6, PHASE_WHOLE_BODY
    ref.root_linvel_h_mps[:] = (0.3, 0.1, 0.0)
    before = stage.solved_ticks
    out = stage.solve(ref, g1.DEFAULT_Q_RAD)
    assert stage.solved_ticks == before + 1
    assert np.all(out.q_rad <= g1.Q_MAX_RAD + 1e-9) and np.all(out.q_rad >= g1.Q_MIN_RAD - 1e-9)
    assert out.q_rad[g1.JOINT_INDEX["left_knee_joint"]] > g1.DEFAULT_Q_RAD[g1.JOINT_INDEX["left_knee_joint"]]
    assert out.upper_body_override and out.pelvis_height_m == 0.6 and out.phase == PHASE_WHOLE_BODY
    assert np.allclose(out.root_linvel_h_mps, (0.3, 0.1, 0.0))


def test_the_velocity_generator_declares_its_references_feasible(stage):
    gen = VelocityReferenceGenerator()
    state = RobotState(q_rad=g1.DEFAULT_Q_RAD.copy())
    gen.reset(state)
    before = stage.solved_ticks
    for k, style in enumerate(("default", "carry", "carry")):
        state.t_s = k * 0.02
        ref = gen.update(Command(vx_mps=0.4, style=style, pelvis_height_m=0.7), state)
        out = stage.solve(ref, state.q_rad)
        assert out is ref.feasible_plan
        assert np.array_equal(out.q_rad, ref.q_rad) and out.root_linvel_h_mps[0] == pytest.approx(0.4)
        assert out.upper_body_override == ref.upper_body_override and out.pelvis_height_m == 0.7
    assert out.upper_body_override  # carry asks for the arms
    assert stage.solved_ticks == before


def test_a_scripted_trajectory_passes_with_its_exact_joint_velocities(stage):
    trajectory = build_reference("arm_wave", duration_s=3.0)
    gen = TrajectoryGenerator(trajectory)
    state = RobotState(q_rad=g1.DEFAULT_Q_RAD.copy())
    gen.reset(state)
    state.t_s = 1.5
    out = stage.solve(gen.update(Command(), state), state.q_rad)
    expected = trajectory.sample(1.5)
    assert out.phase == PHASE_WHOLE_BODY and np.abs(out.dq_radps).max() > 0.1
    assert np.array_equal(out.dq_radps, expected.dq_radps) and np.array_equal(out.q_rad, expected.q_rad)


def test_a_given_solver_is_used_and_described():
    ik = IKRetargeter(IKConfig(dt_s=0.01, iterations=2))
    stage = IKStage(ik)
    assert stage.ik is ik
    assert stage.describe() == "IKStage [feasible plans pass; else daqp QP, 2 iteration(s) at 100 Hz, contacts held]"
