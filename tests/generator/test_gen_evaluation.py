"""The in-betweening harness: metrics, windows, baselines."""

import numpy as np
import pytest

from g1_control.generator import evaluation as E
from g1_control.generator import features as F
from g1_control.generator.baselines import InterpolationInbetweener, MotionMatchingInbetweener
from g1_control.generator.inbetween import InbetweenError
from g1_control.robot import g1


def _walk(n=120, speed=0.5, turn=0.0, seed=0, sway=0.3):
    """A synthetic clip: pelvis moving along an arc, legs and arms swinging (feature frames)."""
    t = np.arange(n) / 30.0
    yaw = turn * t
    root = np.stack([np.cumsum(speed * np.cos(yaw)) / 30, np.cumsum(speed * np.sin(yaw)) / 30,
                     0.75 + 0.01 * np.sin(2 * np.pi * 2 * t)], 1)
    joints = np.tile(g1.DEFAULT_Q_RAD, (n, 1))
    joints[:, 0] += sway * np.sin(2 * np.pi * t + seed)
    joints[:, 6] -= sway * np.sin(2 * np.pi * t + seed)
    joints[:, 15] += sway * np.sin(2 * np.pi * t + seed)
    rot = F.rot_z(yaw)
    return F.fix_effectors(F.world_features(root, rot, joints, np.zeros((n, F.NUM_EFFECTORS, 3))))


def test_perfect_prediction_scores_zero_and_errors_grow_with_noise():
    clips = [_walk(seed=s) for s in range(3)]
    w = E.make_windows(clips, [0, 0, 0], 15)
    stats = E.PositionStats.from_windows(w)
    zero = E.score_predictions("truth", w.truth.copy(), w, stats, 30.0)
    assert zero.l2p == pytest.approx(0.0, abs=1e-9) and zero.l2q == pytest.approx(0.0, abs=1e-9)
    assert zero.npss == pytest.approx(0.0, abs=1e-9)
    small, large = w.truth.copy(), w.truth.copy()
    small[..., F.JOINTS] += 0.01
    large[..., F.JOINTS] += 0.1
    s = E.score_predictions("s", small, w, stats, 30.0)
    lg = E.score_predictions("l", large, w, stats, 30.0)
    assert 0 < s.l2q < lg.l2q and 0 < s.l2p < lg.l2p


def test_windows_are_canonical_in_the_last_context_frame():
    w = E.make_windows([_walk(turn=0.5)], [3], 30)
    last = w.frames[:, 9]
    assert np.allclose(last[:, :2], 0.0, atol=1e-12)
    assert np.allclose(F.yaw_of_matrix(F.rot6d_to_matrix(last[:, F.ROOT_ROT])), 0.0, atol=1e-9)
    assert w.frames.shape[1] == 10 + 30 + 1 and np.all(w.style == 3)


def test_interpolation_is_exact_on_linear_motion():
    w = E.make_windows([_walk(sway=0.0)], [0], 15)
    pred = InterpolationInbetweener().infill(w.context, w.target, np.ones((len(w.frames), F.DIM), bool), 15, w.style)
    assert np.abs(pred[..., :2] - w.truth[..., :2]).max() < 1e-9
    assert np.abs(pred[..., 2] - w.truth[..., 2]).max() < 0.021  # the 1 cm pelvis bob is not linear
    assert np.abs(pred[..., F.JOINTS] - w.truth[..., F.JOINTS]).max() < 1e-9


def test_motion_matching_recovers_a_window_it_has_seen_and_beats_interpolation():
    clips = [_walk(seed=s, turn=0.3 * s) for s in range(4)]
    w = E.make_windows(clips[:1], [0], 15)
    mm = MotionMatchingInbetweener(clips)
    mask = np.ones((len(w.frames), F.DIM), bool)
    pred = mm.infill(w.context, w.target, mask, 15, w.style)
    assert np.abs(pred - w.truth).max() < 1e-6
    stats = E.PositionStats.from_windows(w)
    assert E.score(mm, w, stats).l2q < E.score(InterpolationInbetweener(), w, stats).l2q


def test_infill_refuses_nan_and_bad_gap():
    w = E.make_windows([_walk()], [0], 15)
    ctx = w.context[:1].copy()
    mask = np.ones((1, F.DIM), bool)
    with pytest.raises(InbetweenError, match="gap must be 1..30"):
        InterpolationInbetweener().infill(ctx, w.target[:1], mask, 31, w.style[:1])
    ctx[0, 3, 5] = np.nan
    with pytest.raises(InbetweenError, match="NaN"):
        InterpolationInbetweener().infill(ctx, w.target[:1], mask, 15, w.style[:1])
