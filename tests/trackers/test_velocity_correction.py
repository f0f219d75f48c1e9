import numpy as np

from g1_control.trackers.locomotion import VelocityCorrectionConfig, VelocityCorrector, projected_gravity


def test_integral_raises_command_until_velocity_matches():
    corr = VelocityCorrector(VelocityCorrectionConfig(feedforward=(1, 1, 1), ki=(1, 1, 1)), dt_s=0.02)
    cmd = np.array([0.5, 0.0, 0.0])
    out = [corr(cmd, np.array([0.4, 0.0, 0.0]))[0] for _ in range(200)]
    assert out[0] < out[-1] and out[-1] > 0.55  # too slow -> ask the policy for more
    np.testing.assert_allclose(corr(cmd, np.array([0.5, 0, 0]))[1:], 0.0)  # idle axes untouched


def test_integral_is_bounded_and_resets_when_stopping():
    cfg = VelocityCorrectionConfig(feedforward=(1, 1, 1), ki=(5, 5, 5), integral_limit=(0.2, 0.2, 0.2))
    corr = VelocityCorrector(cfg, dt_s=0.02)
    for _ in range(500):
        out = corr(np.array([0.5, 0, 0]), np.zeros(3))
    assert out[0] == 0.7
    assert np.all(corr(np.zeros(3), np.zeros(3)) == 0) and np.all(corr.integral == 0)


def test_disabled_passes_command_through():
    corr = VelocityCorrector(VelocityCorrectionConfig(enabled=False), dt_s=0.02)
    cmd = np.array([0.3, 0.1, 0.2])
    assert corr(cmd, np.zeros(3)) is cmd


def test_projected_gravity():
    np.testing.assert_allclose(projected_gravity(np.array([1.0, 0, 0, 0])), [0, 0, -1])
    # Pitched 90 deg nose-down (about +y): the body x axis points down, along gravity.
    s = np.sqrt(0.5)
    np.testing.assert_allclose(projected_gravity(np.array([s, 0, s, 0])), [1, 0, 0], atol=1e-12)
