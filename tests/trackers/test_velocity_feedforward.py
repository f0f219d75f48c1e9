"""The velocity correction's feedforward gain is applied (the other tests use a gain of 1, where
dropping it changes nothing)."""

import numpy as np
import pytest

from g1_control.trackers.locomotion import VelocityCorrectionConfig, VelocityCorrector


def test_feedforward_scales_the_moving_axes_only():
    corr = VelocityCorrector(VelocityCorrectionConfig(feedforward=(1.2, 0.8, 1.5), ki=(0, 0, 0)), dt_s=0.02)
    out = corr(np.array([0.5, 0.25, 0.0]), np.array([0.5, 0.25, 0.0]))
    np.testing.assert_allclose(out, [0.6, 0.2, 0.0])


def test_feedforward_and_integral_add():
    corr = VelocityCorrector(VelocityCorrectionConfig(feedforward=(1.1, 1, 1), ki=(2, 0, 0),
                                                      velocity_filter_tau_s=0.0, settle_s=0.0), dt_s=0.02)
    out = corr(np.array([0.5, 0.0, 0.0]), np.array([0.3, 0.0, 0.0]))
    assert out[0] == pytest.approx(1.1 * 0.5 + 2 * (0.5 - 0.3) * 0.02)


def test_a_command_at_the_moving_threshold_counts_as_standing():
    corr = VelocityCorrector(VelocityCorrectionConfig(feedforward=(1.2, 1.2, 1.2), ki=(1, 1, 1)), dt_s=0.02)
    np.testing.assert_array_equal(corr(np.array([0.05, -0.05, 0.0]), np.zeros(3)), [0.05, -0.05, 0.0])


def test_the_integral_is_bounded_below_too():
    """A robot faster than commanded drives the integral negative: bounded at -integral_limit."""
    cfg = VelocityCorrectionConfig(feedforward=(1, 1, 1), ki=(5, 5, 5), integral_limit=(0.2, 0.2, 0.2),
                                   velocity_filter_tau_s=0.0)
    corr = VelocityCorrector(cfg, dt_s=0.02)
    for _ in range(500):
        out = corr(np.array([0.5, 0.0, 0.0]), np.array([1.5, 0.0, 0.0]))
    assert corr.integral[0] == pytest.approx(-0.2) and out[0] == pytest.approx(0.3)


def test_the_velocity_filter_converges_to_a_constant_estimate():
    corr = VelocityCorrector(VelocityCorrectionConfig(velocity_filter_tau_s=0.1), dt_s=0.02)
    for _ in range(300):
        corr(np.array([0.5, 0.0, 0.0]), np.array([0.4, 0.1, -0.2]))
    np.testing.assert_allclose(corr.v_filtered, [0.4, 0.1, -0.2], atol=1e-6)
