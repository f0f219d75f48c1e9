import numpy as np
import pinocchio as pin
import pytest

from g1_control.ik.configuration import Configuration
from g1_control.ik.exceptions import LimitDefinitionError
from g1_control.ik.limits import SelfCollisionLimit, Sphere
from g1_control.robot import g1


def _elbow_near_torso() -> Configuration:
    conf = Configuration()
    q = conf.q.copy()
    q[7 + g1.JOINT_INDEX["left_shoulder_roll_joint"]] = -0.3  # swing the left arm in toward the body
    q[7 + g1.JOINT_INDEX["left_shoulder_yaw_joint"]] = 0.4
    conf.update(q)
    return conf


def test_default_standing_pose_is_clear():
    assert SelfCollisionLimit().distances(Configuration()).min() > 0.04


def test_rows_are_the_jacobian_of_the_active_pair_distances():
    conf = _elbow_near_torso()
    limit = SelfCollisionLimit(activation_m=0.2)
    rows = limit.compute(conf, 0.02)
    active = limit.distances(conf) <= 0.2
    assert rows.matrix.shape[0] == active.sum() > 0
    np.testing.assert_allclose(rows.lower, limit.margin_m - limit.distances(conf)[active], atol=1e-12)
    q0, eps = conf.q.copy(), 1e-6
    fd = np.zeros_like(rows.matrix)
    for i in range(conf.nv):
        step = np.zeros(conf.nv)
        step[i] = eps
        conf.update(pin.integrate(conf.model, q0, step))
        plus = limit.distances(conf)[active]
        conf.update(pin.integrate(conf.model, q0, -step))
        fd[:, i] = (plus - limit.distances(conf)[active]) / (2 * eps)
    np.testing.assert_allclose(rows.matrix, fd, atol=2e-6)


def test_far_pairs_add_no_rows_and_bad_setups_are_refused():
    far = (Sphere("left_rubber_hand", (0, 0, 0), 0.01), Sphere("right_ankle_roll_link", (0, 0, 0), 0.01))
    assert SelfCollisionLimit(pairs=(far,)).compute(Configuration(), 0.02) is None
    with pytest.raises(LimitDefinitionError, match="0 <= margin_m < activation_m"):
        SelfCollisionLimit(margin_m=0.2, activation_m=0.1)
    same = (Sphere("pelvis", (0, 0, 0), 0.1), Sphere("pelvis", (0, 0, 0.1), 0.1))
    with pytest.raises(LimitDefinitionError, match="one frame 'pelvis'"):
        SelfCollisionLimit(pairs=(same,))


def test_missed_pairs_are_those_inside_the_margin_the_last_compute_gave_no_row():
    limit = SelfCollisionLimit()
    q = Configuration().q.copy()
    q[7 + g1.JOINT_INDEX["left_shoulder_roll_joint"]] = 0.8  # left arm well out to the side
    out = Configuration(q)
    elbow_chest = next(i for i, (a, b) in enumerate(limit.pairs)
                       if a.frame == "left_elbow_link" and b.frame == "torso_link")
    assert limit.distances(out)[elbow_chest] > limit.activation_m
    limit.compute(out, 0.02)  # the QP of a step from `out`: no row for the elbow
    assert not limit.missed_pairs(out).any()
    q[7 + g1.JOINT_INDEX["left_shoulder_roll_joint"]] = -0.3  # where a large step took it: in the chest
    q[7 + g1.JOINT_INDEX["left_shoulder_yaw_joint"]] = 0.4
    inside = Configuration(q)
    missed = limit.missed_pairs(inside)
    assert missed[elbow_chest] and (limit.distances(inside)[missed] < limit.margin_m).all()
    # `include` gives a pair a row whatever its distance, and a pair with a row is never missed
    limit.include[elbow_chest] = True
    rows = limit.compute(out, 0.02)
    assert np.isclose(rows.lower, limit.margin_m - limit.distances(out)[elbow_chest]).any()
    assert not limit.missed_pairs(inside)[elbow_chest]
