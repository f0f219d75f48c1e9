"""Scripted references: what each promises (planted feet, crouch depth, speed, schedule)."""

import numpy as np
import pytest

from g1_control.errors import WbcConfigError
from g1_control.generator import scripted as R
from g1_control.ik.whole_body import WholeBodyIK
from g1_control.robot.dynamics import SOLE_FRAMES


@pytest.fixture(scope="module")
def ik():
    return WholeBodyIK()


def pin_q(j):
    w, x, y, z = j.root_quat_wxyz
    return np.concatenate([j.root_pos_w_m, [x, y, z, w], j.q_rad])


def sole_positions(ik, traj, times):
    return np.array([[ik.frame_pose(pin_q(traj.sample(t)), n)[0] for n in SOLE_FRAMES] for t in times])


def test_crouch_goes_down_15_cm_with_feet_planted(ik):
    traj = R.crouch()
    t = np.linspace(0, traj.duration_s, 60)
    z = np.array([traj.sample(tk).root_pos_w_m[2] for tk in t])
    assert z[0] - z.min() == pytest.approx(0.15, abs=0.002)
    assert z[-1] == pytest.approx(z[0], abs=1e-3)
    soles = sole_positions(ik, traj, t)
    assert np.abs(soles - soles[0]).max() < 2e-3


def test_lean_reach_puts_the_hand_near_the_point_ahead(ik):
    traj = R.lean_reach()
    reached = traj.extras["hand_reference_w_m"]
    assert reached[0] > 0.49 and np.linalg.norm(reached - traj.extras["hand_target_w_m"]) < 0.015


def test_walk_moves_at_the_commanded_speed_with_alternating_single_support(ik):
    traj = R.walk(speed_mps=0.3, n_steps=6)
    # steady part: from the first to the last single support
    single = ~traj.contacts.all(axis=1)
    t0, t1 = traj.t_s[single][0], traj.t_s[single][-1]
    x0, x1 = traj.sample(t0).root_pos_w_m[0], traj.sample(t1).root_pos_w_m[0]
    assert (x1 - x0) / (t1 - t0) == pytest.approx(0.3, rel=0.15)
    swings = traj.contacts[single].argmin(axis=1)
    changes = np.flatnonzero(np.diff(swings)) + 1
    assert len(changes) == 6  # six steps and the closing one, alternating feet
    assert np.all(traj.contacts.any(axis=1))


def test_sampled_velocities_match_finite_differences():
    traj = R.arm_wave(duration_s=4.0)
    a, b = traj.sample(2.0), traj.sample(2.0 + 1e-5)
    np.testing.assert_allclose((b.q_rad - a.q_rad) / 1e-5, a.dq_radps, atol=1e-3)


def test_unknown_reference_and_bad_trajectory_are_refused():
    with pytest.raises(WbcConfigError, match="unknown WBC reference 'dance'"):
        R.build_reference("dance")
    with pytest.raises(WbcConfigError, match="no foot in contact"):
        R.WholeBodyTrajectory("x", np.array([0.0, 1.0]), np.zeros((2, 3)), np.zeros((2, 3)), np.zeros((2, 29)),
                              np.zeros((2, 2), dtype=bool))
    with pytest.raises(WbcConfigError, match="q_rad has shape"):
        R.WholeBodyTrajectory("x", np.array([0.0, 1.0]), np.zeros((2, 3)), np.zeros((2, 3)), np.zeros((2, 28)),
                              np.ones((2, 2), dtype=bool))
