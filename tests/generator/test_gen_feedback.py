"""Reference-guided feedback: pulls poses off the style's reference mixture back toward it,
leaves supported poses alone, switches per style, and is disabled near a goal."""

import numpy as np
import pytest

from g1_control.generator import features as F
from g1_control.generator.feedback import (
    FeedbackInbetweener,
    Mixture,
    ReferenceFeedback,
    feedback_columns,
    load_mixtures,
    save_mixtures,
)
from g1_control.robot import g1
from g1_control.training.mixtures import fit_gmm


def _mixture(centre: float, spread: float = 0.05, skeleton: str = "g1_29dof", seed: int = 0) -> Mixture:
    cols = feedback_columns(skeleton)
    rng = np.random.default_rng(seed)
    z = centre + spread * rng.normal(size=(2000, len(cols)))
    w, mu, var = fit_gmm(z, k=3, seed=seed)
    return Mixture(w, mu, var, cols)


def _frames(n: int, value: float) -> np.ndarray:
    out = np.zeros((n, F.DIM))
    out[:, F.JOINT_SLOTS] = value
    out[:, 2] = value
    return out


def test_gmm_fit_recovers_two_separated_clusters():
    rng = np.random.default_rng(0)
    z = np.concatenate([rng.normal(-1.0, 0.1, size=(500, 2)), rng.normal(2.0, 0.2, size=(1500, 2))])
    w, mu, var = fit_gmm(z, k=2)
    order = np.argsort(mu[:, 0])
    assert np.allclose(mu[order, 0], [-1.0, 2.0], atol=0.05)
    assert np.allclose(w[order], [0.25, 0.75], atol=0.02)
    assert np.allclose(np.sqrt(var[order, 0]), [0.1, 0.2], atol=0.02)


def test_feedback_pulls_far_poses_back_and_leaves_supported_ones_alone():
    fb = ReferenceFeedback({"default": _mixture(0.3)}, strength=1.0, tau=1.5)
    cols = fb.mixture.columns
    near = _frames(4, 0.3)
    assert np.allclose(fb.apply(near, np.ones(4)), near)  # within tau: untouched
    far = _frames(4, 0.8)  # ten standard deviations off
    out = fb.apply(far, np.ones(4))
    before = np.abs(far[:, cols] - 0.3).mean()
    after = np.abs(out[:, cols] - 0.3).mean()
    assert after < 0.25 * before
    # only the covered features move (legs, root x/y and rotation, effectors stay)
    other = np.setdiff1d(np.arange(F.DIM), cols)
    assert np.array_equal(out[:, other], far[:, other])
    legs = F.JOINT_SLOTS[list(g1.LEG_JOINTS)]
    assert not np.isin(legs, cols).any()


def test_feedback_is_disabled_near_a_goal_in_time_and_in_space():
    fb = ReferenceFeedback({"default": _mixture(0.3)}, strength=0.5, fade_frames=8, near_m=(0.1, 0.35))
    w = fb.frame_weights(30, goal_frames=[20])
    assert w[20] == 0.0 and w[19] < 0.1 and w[0] == pytest.approx(0.5) and w[29] == pytest.approx(0.5)
    assert np.all(np.diff(w[12:21]) <= 0)  # fades in as the goal frame approaches
    w = fb.frame_weights(30, target_frame=30)
    assert w[29] == pytest.approx(0.5 / 8) and w[0] == pytest.approx(0.5)
    frames = _frames(30, 0.8)
    hand = F.effector_slice("right_wrist_yaw_link")
    goal = np.array([0.4, -0.2, 1.0])
    frames[:, hand] = goal + np.linspace(1.0, 0.0, 30)[:, None] * np.array([0.5, 0.0, 0.0])
    w = fb.frame_weights(30, frames=frames, effector_goals=[(np.r_[hand], goal)])
    assert w[-1] == 0.0 and w[0] == pytest.approx(0.5)  # hand at the goal: off; 0.5 m away: on
    out = fb.apply(frames, w)
    assert np.array_equal(out[-1], frames[-1]) and not np.array_equal(out[0], frames[0])


def test_mixture_is_switched_per_style_at_run_time_and_round_trips(tmp_path):
    mixtures = {"default": _mixture(0.3), "wave": _mixture(-0.4, seed=1)}
    save_mixtures({"g1_29dof": mixtures}, tmp_path / "feedback.npz")
    loaded = load_mixtures(tmp_path / "feedback.npz", "g1_29dof")
    assert set(loaded) == {"default", "wave"}
    fb = ReferenceFeedback(loaded, strength=1.0)
    frames = _frames(2, 0.0)
    fb.set_style("default")
    up = fb.apply(frames, np.ones(2))[:, fb.mixture.columns].mean()
    fb.set_style("wave")
    down = fb.apply(frames, np.ones(2))[:, fb.mixture.columns].mean()
    assert up > 0.05 and down < -0.05
    fb.set_style("unknown_style")  # falls back to the default style's mixture
    assert fb.mixture is loaded["default"]
    fb.set_mixtures({"default": _mixture(-0.4, seed=2)})
    assert fb.apply(frames, np.ones(2))[:, fb.mixture.columns].mean() < -0.05


def test_feedback_columns_follow_the_skeleton():
    c29, c23, ch = (feedback_columns(s) for s in ("g1_29dof", "g1_23dof", "g1_29dof_with_hand"))
    assert len(c29) == 1 + 17 and len(c23) == 1 + 11 and len(ch) == 1 + 17 + 14
    assert F.JOINT_SLOTS[g1.JOINT_INDEX["waist_pitch_joint"]] in c29
    assert F.JOINT_SLOTS[g1.JOINT_INDEX["waist_pitch_joint"]] not in c23


def test_feedback_inbetweener_fades_to_the_target():
    from g1_control.generator.baselines import InterpolationInbetweener

    fb = ReferenceFeedback({"default": _mixture(0.3)}, strength=1.0)
    ctx = np.repeat(_frames(1, 0.8)[None], 10, axis=1)
    ctx[..., 3], ctx[..., 7] = 1.0, 1.0
    wrapped = FeedbackInbetweener(InterpolationInbetweener(), fb)
    mask = np.ones((1, F.DIM), bool)
    out = wrapped.infill(ctx, ctx[:, -1], mask, 20, np.zeros(1, int))
    plain = InterpolationInbetweener().infill(ctx, ctx[:, -1], mask, 20, np.zeros(1, int))
    cols = fb.mixture.columns
    moved = np.abs(out[0, :, cols] - plain[0, :, cols]).mean(axis=0)
    assert moved[0] > 0.1 and moved[-1] < moved[0] / 4
