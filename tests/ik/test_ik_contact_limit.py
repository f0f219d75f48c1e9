import numpy as np
import pinocchio as pin
import pytest
from test_ik_frame_task import random_configuration

from g1_control.ik.limits import ContactLimit


class _ErrorOf:
    def __init__(self, limit):
        self.limit = limit

    def compute_error(self, conf):
        return self.limit.error(conf)


def test_contact_rows_are_the_jacobian_of_the_drift():
    from test_ik_frame_task import fd_jacobian

    conf = random_configuration(10)
    limit = ContactLimit("left_ankle_roll_link")
    limit.set_anchor(pin.SE3(pin.utils.rpyToMatrix(0.1, 0.0, 0.3), np.array([0.1, 0.1, 0.05])))
    rows = limit.compute(conf, 0.02)
    assert rows.equality
    np.testing.assert_allclose(rows.matrix, fd_jacobian(_ErrorOf(limit), conf), atol=2e-6)
    np.testing.assert_allclose(rows.lower, -limit.error(conf))


def test_released_contact_adds_nothing():
    conf = random_configuration(11)
    limit = ContactLimit("left_ankle_roll_link", position_only=True)
    assert limit.compute(conf, 0.02) is None
    limit.set_anchor(pin.SE3.Identity())
    assert limit.compute(conf, 0.02).matrix.shape == (3, conf.nv)
    limit.release()
    assert not limit.active and limit.compute(conf, 0.02) is None


def test_free_yaw_rows_are_the_jacobian_of_position_and_tilt():
    from test_ik_frame_task import fd_jacobian

    conf = random_configuration(14)
    limit = ContactLimit("right_ankle_roll_link", free_yaw=True)
    limit.set_anchor(pin.SE3(pin.utils.rpyToMatrix(0.05, -0.1, 1.0), np.array([0.0, -0.1, 0.04])))
    rows = limit.compute(conf, 0.02)
    assert rows.matrix.shape == (5, conf.nv)
    np.testing.assert_allclose(rows.matrix, fd_jacobian(_ErrorOf(limit), conf), atol=2e-6)
    # yaw is free: two level anchors that differ only in yaw see the same tilt error (its norm is
    # the horizontal part of the foot's z axis) and the same position error
    a = ContactLimit("right_ankle_roll_link", free_yaw=True)
    b = ContactLimit("right_ankle_roll_link", free_yaw=True)
    a.set_anchor(pin.SE3(pin.utils.rpyToMatrix(0.0, 0.0, 0.3), np.zeros(3)))
    b.set_anchor(pin.SE3(pin.utils.rpyToMatrix(0.0, 0.0, -2.0), np.zeros(3)))
    ea, eb = a.error(conf), b.error(conf)
    np.testing.assert_allclose(ea[:3], eb[:3])
    assert np.linalg.norm(ea[3:]) == pytest.approx(np.linalg.norm(eb[3:]), abs=1e-12)
