"""Joint-level goals in the runtime: reaching primitives, goals on gap frames, subsets per
skeleton, and the feedback switched off near a goal (interpolation in-betweener, so these do not
depend on a trained model)."""

import numpy as np
import pytest

from g1_control.generator import features as F
from g1_control.generator.baselines import InterpolationInbetweener
from g1_control.generator.feedback import Mixture, ReferenceFeedback, feedback_columns
from g1_control.generator.runtime import InbetweeningGenerator, hand_forward_m
from g1_control.generator.style_stats import StyleStats
from g1_control.robot import g1
from g1_control.types import Command, EffectorGoal, RobotState


class Recorder(InterpolationInbetweener):
    """Interpolation that records the goals and masks it was given."""

    def __init__(self):
        self.calls = []
        self._goal = None

    def set_goals(self, goal, mask):
        self._goal = (goal, mask)

    def infill(self, context, target, target_mask, gap, style):
        self.calls.append((target.copy(), target_mask.copy(), self._goal))
        self._goal = None
        return super().infill(context, target, target_mask, gap, style)


def _styles():
    wave = g1.DEFAULT_Q_RAD.copy()
    wave[g1.JOINT_INDEX["right_shoulder_pitch_joint"]] = -1.2
    wave[g1.JOINT_INDEX["left_shoulder_pitch_joint"]] = 0.4
    wave[g1.JOINT_INDEX["waist_pitch_joint"]] = 0.3
    return {"default": StyleStats("default", g1.DEFAULT_Q_RAD.copy(), (0.74, 0.76, 0.79)),
            "wave": StyleStats("wave", wave, (0.66, 0.70, 0.73))}


def _run(gen, command, seconds, hz=30.0):
    state = RobotState(q_rad=g1.DEFAULT_Q_RAD.copy(), base_pos_w_m=np.array([0.0, 0.0, 0.76]))
    ref = None
    for i in range(int(seconds * hz)):
        state.t_s = i / hz
        ref = gen.update(command, state)
    return ref


def _gen(skeleton="g1_29dof", feedback=None):
    rec = Recorder()
    gen = InbetweeningGenerator(rec, _styles(), skeleton=skeleton, feedback=feedback)
    gen.reset(RobotState(q_rad=g1.DEFAULT_Q_RAD.copy(), base_pos_w_m=np.array([0.0, 0.0, 0.76])))
    return gen, rec


def test_far_hand_goal_is_walked_to_then_given_on_the_keyframe_and_the_last_plan_frame():
    gen, rec = _gen()
    goal = np.array([1.5, 0.5, 1.0])
    ref = _run(gen, Command(goals=[EffectorGoal("right_wrist_yaw_link", goal)]), 6.0)
    hand = F.effector_slice("right_wrist_yaw_link")
    _, mask, goals = rec.calls[0]
    assert not mask[0, hand].any() and goals is None  # 1.6 m away: walk first, no hand goal yet
    assert np.linalg.norm(ref.root_pos_w_m[:2] - goal[:2]) < 0.4  # arrived next to it
    yaw = np.arctan2(2 * ref.root_quat_wxyz[0] * ref.root_quat_wxyz[3], 1 - 2 * ref.root_quat_wxyz[3] ** 2)
    to_goal = np.arctan2(goal[1] - ref.root_pos_w_m[1], goal[0] - ref.root_pos_w_m[0])
    assert abs((yaw - to_goal + np.pi) % (2 * np.pi) - np.pi) < 0.8  # facing it (the hand is off to the side)
    _, mask, (_, gap_mask) = rec.calls[-1]
    assert mask[0, hand].all() and mask[0, F.ROOT].all()
    frames = np.flatnonzero(gap_mask[0].any(axis=1))
    # the hand (only), from the frame it can reach the goal at hand speed, held every 2 frames to the end
    assert gap_mask[0][:, hand].all(axis=1)[frames].all() and gap_mask[0].sum() == 3 * len(frames)
    assert frames[0] >= 8 and np.all(np.diff(frames) == 2) and frames[-1] >= 28
    assert np.allclose(ref.frame_targets_w["right_wrist_yaw_link"][:3], goal)


def test_goal_at_a_time_lands_on_that_gap_frame_and_frees_the_goal_arm_of_the_style_pose():
    gen, rec = _gen()
    goal = np.array([0.2, -0.2, 1.0])  # within reach of where the robot stands
    _run(gen, Command(style="wave", goals=[EffectorGoal("right_wrist_yaw_link", goal, t_s=0.5)]), 0.2)
    _, mask, (gap_goal, gap_mask) = rec.calls[-1]
    frames = np.flatnonzero(gap_mask[0].any(axis=1))
    assert list(frames) == [14]  # 0.5 s at 30 fps: the 15th planned frame
    right = [9 + g1.JOINT_INDEX[f"right_{n}_joint"] for n in ("shoulder_pitch", "elbow", "wrist_yaw")]
    left = [9 + g1.JOINT_INDEX[f"left_{n}_joint"] for n in ("shoulder_pitch", "elbow")]
    assert not mask[0, right].any() and mask[0, left].all()  # style pose for the other arm only
    assert np.allclose(gap_goal[0, 14, F.effector_slice("right_wrist_yaw_link")][2], goal[2])  # height is frame-invariant


def test_pelvis_and_head_goals_and_skeleton_subsets():
    gen, rec = _gen(skeleton="g1_23dof")
    ref = _run(gen, Command(style="wave", goals=[EffectorGoal("pelvis", np.array([0.8, 0.0, 0.7]))]), 5.0)
    assert np.linalg.norm(ref.root_pos_w_m[:2] - [0.8, 0.0]) < 0.1 and ref.root_pos_w_m[2] == pytest.approx(0.7, abs=0.03)
    _, mask, _ = rec.calls[-1]
    waist_pitch = 9 + g1.JOINT_INDEX["waist_pitch_joint"]
    assert not mask[0, waist_pitch]  # the 23-DoF G1 has no waist pitch: never given ...
    assert ref.q_rad[g1.JOINT_INDEX["waist_pitch_joint"]] == 0.0  # ... and never commanded
    assert ref.hand_q_rad is None
    gen, rec = _gen(skeleton="g1_29dof_with_hand")
    ref = _run(gen, Command(goals=[EffectorGoal("head", np.array([0.15, 0.0, 1.15]))]), 1.0)
    _, mask, _ = rec.calls[-1]
    assert mask[0, F.effector_slice("head")].all() and ref.hand_q_rad.shape == (14,)


def test_hand_reach_distance_shrinks_away_from_shoulder_height():
    level = hand_forward_m(0.76 + 0.29, 0.76)
    assert level == pytest.approx(0.22) and hand_forward_m(1.3, 0.76) < 0.15 and hand_forward_m(0.2, 0.76) == 0.05


def _far_mixture(skeleton="g1_29dof"):
    cols = feedback_columns(skeleton)
    means = np.full((1, len(cols)), -0.5)
    means[0, 0] = 0.7  # pelvis height column
    return Mixture(np.ones(1), means, np.full((1, len(cols)), 1e-3), cols)


def test_runtime_feedback_pulls_plans_toward_the_style_but_not_near_a_goal():
    fb = ReferenceFeedback({"default": _far_mixture()}, strength=0.5)
    plain, _ = _gen()
    fed, _ = _gen(feedback=fb)
    a, b = _run(plain, Command(), 1.0), _run(fed, Command(), 1.0)
    j = g1.JOINT_INDEX["left_elbow_joint"]
    assert b.q_rad[j] < a.q_rad[j] - 0.1  # pulled toward the (far) reference pose
    # a hand goal the hand already sits at: the feedback is off on the arm near it
    plain, _ = _gen()
    state_hand = plain.history[-1][F.effector_slice("right_wrist_yaw_link")].copy()
    cmd = Command(goals=[EffectorGoal("right_wrist_yaw_link", state_hand)])
    fed, _ = _gen(feedback=ReferenceFeedback({"default": _far_mixture()}, strength=0.5))
    _run(fed, cmd, 0.1)
    n = len(fed.plan)
    w = fed.feedback.frame_weights(n, [n - 1], n, fed.plan, [(np.r_[F.effector_slice("right_wrist_yaw_link")],
                                                           state_hand)])
    assert w[-1] == 0.0 and w.max() < 0.5  # near the goal in time and in space
