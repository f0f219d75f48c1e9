"""What the generators hand the styled-walking tracker: blended style changes and a planned pelvis
height from the velocity generator; plans whose waist does not carry the library's old sag."""

import numpy as np
import pytest

from g1_control.generator.baselines import InterpolationInbetweener
from g1_control.generator.runtime import InbetweeningGenerator, RuntimeConfig
from g1_control.generator.style_stats import StyleStats
from g1_control.generator.styles import ROLLOUT_STYLES
from g1_control.generator.velocity import VelocityReferenceGenerator
from g1_control.robot import g1
from g1_control.types import Command, JointReference, RobotState

SHOULDER = g1.JOINT_INDEX["left_shoulder_pitch_joint"]
PITCH = g1.JOINT_INDEX["waist_pitch_joint"]


def _step(gen, command, state, t):
    state.t_s = t
    plan = gen.update(command, state).feasible_plan  # feasible by construction: what the IK stage passes on
    assert plan is not None
    return JointReference().copy_from(plan)


def test_style_change_blends_and_hands_back_after_the_blend():
    gen = VelocityReferenceGenerator(blend_s=0.5)
    state = RobotState(q_rad=g1.DEFAULT_Q_RAD.copy())
    gen.reset(state)
    ref = _step(gen, Command(), state, 0.0)
    assert not ref.upper_body_override and ref.pelvis_height_m is None
    carry = ROLLOUT_STYLES["carry"].pose(0.0)
    ref = _step(gen, Command(style="carry"), state, 1.0)  # the switch: still at the measured arms
    assert ref.upper_body_override and ref.q_rad[SHOULDER] == pytest.approx(g1.DEFAULT_Q_RAD[SHOULDER])
    ref = _step(gen, Command(style="carry"), state, 1.25)  # half way
    assert ref.q_rad[SHOULDER] == pytest.approx(0.5 * (g1.DEFAULT_Q_RAD[SHOULDER] + carry[SHOULDER]))
    ref = _step(gen, Command(style="carry"), state, 1.6)
    assert ref.q_rad[SHOULDER] == pytest.approx(carry[SHOULDER])
    ref = _step(gen, Command(), state, 2.0)  # back to the policy's own arms: blended first
    assert ref.upper_body_override and ref.q_rad[SHOULDER] == pytest.approx(carry[SHOULDER])
    ref = _step(gen, Command(), state, 2.3)
    assert ref.upper_body_override
    ref = _step(gen, Command(), state, 2.6)
    assert not ref.upper_body_override
    np.testing.assert_array_equal(ref.q_rad, g1.DEFAULT_Q_RAD)


def test_velocity_generator_passes_the_planned_pelvis_height():
    gen = VelocityReferenceGenerator()
    state = RobotState(q_rad=g1.DEFAULT_Q_RAD.copy())
    gen.reset(state)
    assert _step(gen, Command(vx_mps=0.3, pelvis_height_m=0.65), state, 0.0).pelvis_height_m == 0.65


def test_runtime_plans_keep_the_waist_up_whatever_the_style_statistics_say():
    sagged = g1.DEFAULT_Q_RAD.copy()
    sagged[PITCH] = 0.5  # what the shipped style_stats.json holds for carry, wave, reach_up
    sagged[SHOULDER] = -0.8
    styles = {"default": StyleStats("default", g1.DEFAULT_Q_RAD.copy(), (0.74, 0.76, 0.79)),
              "carry": StyleStats("carry", sagged, (0.64, 0.68, 0.72))}
    gen = InbetweeningGenerator(InterpolationInbetweener(), styles, RuntimeConfig(max_waist_lean_rad=0.2))
    state = RobotState(q_rad=g1.DEFAULT_Q_RAD.copy(), base_pos_w_m=np.array([0.0, 0.0, 0.76]))
    gen.reset(state)
    pitches = []
    for i in range(100):
        state.t_s = i / 50
        ref = gen.update(Command(vx_mps=0.3, style="carry"), state)
        pitches.append(ref.q_rad[PITCH])
    assert max(pitches) <= 0.2 + 1e-9
    assert ref.q_rad[SHOULDER] == pytest.approx(-0.8, abs=0.05)  # the arms still follow the style
    assert ref.pelvis_height_m is None
