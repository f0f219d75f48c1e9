"""VelocityCorrector's settle time and its held-at-zero axes (mutation-run survivors, issue 16).

dt 0.25 s and settle 0.5 s are exact in binary, so "more than settle_s" is tested at its boundary."""

from __future__ import annotations

import numpy as np

from g1_control.trackers.locomotion import VelocityCorrectionConfig, VelocityCorrector


def _corrector() -> VelocityCorrector:
    cfg = VelocityCorrectionConfig(feedforward=(1, 1, 1), ki=(1, 1, 1), integral_limit=(1, 1, 1), settle_s=0.5)
    return VelocityCorrector(cfg, dt_s=0.25)


def test_an_axis_held_at_zero_is_corrected_only_after_settle_s_from_standing():
    corr = _corrector()
    assert np.all(corr(np.zeros(3), np.zeros(3)) == 0.0)  # standing
    walk, drifting = np.array([0.5, 0.0, 0.0]), np.array([0.5, 0.2, 0.0])
    first, second, third = (corr(walk, drifting) for _ in range(3))
    assert first[1] == 0.0 and second[1] == 0.0, "0.25 s and 0.5 s walking: not more than settle_s yet"
    assert third[1] < 0.0, "0.75 s: the sideways drift is pushed back towards zero"
    assert first[0] == second[0] == 0.5 and third[0] > 0.5, "the commanded axis waits as long"


def test_an_axis_restarted_while_another_walks_waits_settle_s_again():
    corr = _corrector()
    slow = np.array([0.4, 0.0, 0.0])
    for _ in range(4):
        corr(np.array([0.5, 0.0, 0.0]), slow)
    assert corr.integral[0] > 0.0 and corr.integral[1] == 0.0
    turn = np.array([0.5, 0.0, 0.3])
    out = corr(turn, slow)
    assert corr.integral[2] == 0.0 and out[2] == 0.3, "the yaw command just started"
    assert corr.integral[0] > 0.0, "the forward axis keeps its integral"


def test_the_state_is_one_value_per_axis():
    corr = _corrector()
    for cmd in (np.zeros(3), np.array([0.5, 0.0, 0.0])):
        corr(cmd, np.zeros(3))
        assert corr.integral.shape == (3,) and corr.moving_s.shape == (3,) and corr.v_filtered.shape == (3,)


def test_reset_starts_over_as_a_new_corrector():
    used = _corrector()
    for _ in range(6):
        used(np.array([0.5, 0.0, 0.2]), np.array([0.3, 0.1, 0.0]))
    assert np.any(used.integral != 0.0) and np.any(used.v_filtered != 0.0) and np.any(used.moving_s != 0.0)
    used.reset()
    assert np.all(used.integral == 0.0) and np.all(used.v_filtered == 0.0) and np.all(used.moving_s == 0.0)
    fresh = _corrector()
    for cmd, v in [((0.0, 0.4, 0.0), (0.0, 0.2, 0.1))] * 5 + [((0.5, 0.0, 0.0), (0.4, 0.0, 0.0))] * 4:
        np.testing.assert_array_equal(used(np.array(cmd), np.array(v)), fresh(np.array(cmd), np.array(v)))
