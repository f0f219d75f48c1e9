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
                                                      velocity_filter_tau_s=0.0), dt_s=0.02)
    out = corr(np.array([0.5, 0.0, 0.0]), np.array([0.3, 0.0, 0.0]))
    assert out[0] == pytest.approx(1.1 * 0.5 + 2 * (0.5 - 0.3) * 0.02)
