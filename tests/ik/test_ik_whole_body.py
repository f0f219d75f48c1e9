"""WholeBodyIK: the pose solver of planned whole-body references (soles, CoM, pelvis, hands), with
the joint limits inside its iteration."""

import numpy as np
import pytest

from g1_control.ik.whole_body import LIMIT_MARGIN_RAD, WholeBodyIK
from g1_control.robot import g1
from g1_control.robot.dynamics import SOLE_FRAMES

LO, HI = g1.Q_MIN_RAD + LIMIT_MARGIN_RAD, g1.Q_MAX_RAD - LIMIT_MARGIN_RAD


@pytest.fixture(scope="module")
def ik():
    return WholeBodyIK()


def _soles(ik, q):
    return [ik.frame_pose(q, name) for name in SOLE_FRAMES]


def _sole_error_m(ik, q, soles):
    return max(float(np.linalg.norm(ik.frame_pose(q, name)[0] - pos)) for name, (pos, _) in zip(SOLE_FRAMES, soles))


def test_nominal_stands_on_the_floor_above_the_origin(ik):
    q = ik.nominal()
    assert np.allclose(q[:2], 0.0) and np.array_equal(q[7:], g1.DEFAULT_Q_RAD)
    assert all(abs(pos[2]) < 1e-9 for pos, _ in _soles(ik, q))
    assert 0.7 < q[2] < 0.8


def test_a_crouch_keeps_the_feet_and_the_com_where_they_were(ik):
    q0 = ik.nominal()
    soles, com = _soles(ik, q0), ik.com(q0)[:2]
    q = q0
    for drop in np.linspace(0.0, 0.15, 16):  # as a plan does it: a little per sample
        q = ik.solve(q, soles, com, q0[2] - drop, np.eye(3), g1.DEFAULT_Q_RAD, iterations=8)
    assert abs(q[2] - (q0[2] - 0.15)) < 2e-3
    assert _sole_error_m(ik, q, soles) < 5e-4 and np.linalg.norm(ik.com(q)[:2] - com) < 1e-3


def test_a_hand_reaches_a_point_in_front(ik):
    q0 = ik.nominal()
    soles, com = _soles(ik, q0), ik.com(q0)[:2]
    target = np.array([0.4, -0.2, 0.9])
    q = ik.solve(q0, soles, com, None, np.eye(3), g1.DEFAULT_Q_RAD, hands=[("right_hand", target)],
                 hand_weight=100.0, iterations=60)
    assert np.linalg.norm(ik.frame_pose(q, "right_hand")[0] - target) < 2e-3
    assert _sole_error_m(ik, q, soles) < 5e-4


def test_joints_stop_at_their_limits_when_the_targets_ask_for_more(ik):
    q0 = ik.nominal()
    soles, com = _soles(ik, q0), ik.com(q0)[:2]
    # a point behind and below the robot: no pose reaches it, the joints on the way end at their limits
    q = ik.solve(q0, soles, com, None, np.eye(3), g1.DEFAULT_Q_RAD, hands=[("right_hand", np.array([-1.0, -1.0, 0.0]))],
                 hand_weight=100.0, iterations=60)
    joints = q[7:]
    assert np.all(joints >= LO - 1e-12) and np.all(joints <= HI + 1e-12)
    assert np.sum((joints <= LO + 1e-6) | (joints >= HI - 1e-6)) >= 2
    # a posture beyond every upper limit: each joint lands on its limit less the margin, not past it
    q = ik.solve(q0, soles, com, None, np.eye(3), g1.Q_MAX_RAD + 1.0, posture_weight=1.0, iterations=60)
    assert np.all(q[7:] <= HI + 1e-12)
