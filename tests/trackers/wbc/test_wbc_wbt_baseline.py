"""The WBT comparison baseline: observation layout and action mapping."""

import numpy as np

from g1_control.generator import scripted as R
from g1_control.robot import g1
from g1_control.sim.mujoco_backend import MujocoBackend
from g1_control.trackers.wbt import WbtPolicyTracker


def test_observation_layout_and_action_mapping():
    tracker = WbtPolicyTracker()
    state = MujocoBackend().reset()
    ref = R.stand(1.0).sample(0.0)
    cmd = tracker.act(ref, state)
    obs = tracker._obs[0]
    assert obs.shape == (154,)
    np.testing.assert_allclose(obs[:29], 0.0)  # no previous action
    np.testing.assert_allclose(obs[29:32], state.imu_gyro_radps, atol=1e-6)
    np.testing.assert_allclose(obs[32:61], state.q_rad - g1.DEFAULT_Q_RAD, atol=1e-6)
    np.testing.assert_allclose(obs[90:119], ref.q_rad, atol=1e-6)  # motion_command: positions, then velocities
    np.testing.assert_allclose(obs[148:], [1, 0, 0, 1, 0, 0], atol=1e-3)  # same torso orientation
    np.testing.assert_allclose(cmd.q_rad, tracker.default_q + tracker.action_scale * tracker.last_action)
    np.testing.assert_allclose(tracker.kp, g1.KP_DEFAULT, rtol=1e-6)
    # the scale is 0.25 * effort / kp, e.g. knee 0.25 * 139 / 99.1
    assert tracker.action_scale[3] == np.float64(0.25 * 139.0 / tracker.kp[3])
