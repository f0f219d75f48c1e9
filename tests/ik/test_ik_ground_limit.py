import numpy as np
import pinocchio as pin
from test_ik_frame_task import random_configuration

from g1_control.ik.configuration import Configuration, foot_contact_points
from g1_control.ik.limits import GroundLimit
from g1_control.robot import g1


def test_foot_spheres_come_from_the_urdf():
    points = foot_contact_points()
    assert set(points) == set(g1.FOOT_BODIES)
    assert all(len(v) == 4 for v in points.values())
    # sole 3.5 cm below the ankle-roll frame: sphere centres at -3 cm, radius 5 mm (URDF)
    centres = np.array([c for c, _ in points["left_ankle_roll_link"]])
    np.testing.assert_allclose(centres[:, 2], -0.03)


def test_rows_lower_bound_is_minus_the_height_of_each_sphere_bottom():
    conf = Configuration()
    limit = GroundLimit(ground_height_m=0.01, tolerance_m=1e-4)
    rows = limit.compute(conf, 0.02)
    np.testing.assert_allclose(rows.lower, -limit.point_heights(conf) - 1e-4, atol=1e-12)


def test_rows_are_the_jacobian_of_the_point_heights():
    conf = random_configuration(12)
    limit = GroundLimit()
    rows = limit.compute(conf, 0.02).matrix.copy()
    q0 = conf.q.copy()
    eps = 1e-6
    fd = np.zeros_like(rows)
    for i in range(conf.nv):
        step = np.zeros(conf.nv)
        step[i] = eps
        conf.update(pin.integrate(conf.model, q0, step))
        plus = limit.point_heights(conf)
        conf.update(pin.integrate(conf.model, q0, -step))
        fd[:, i] = (plus - limit.point_heights(conf)) / (2 * eps)
    np.testing.assert_allclose(rows, fd, atol=2e-6)
