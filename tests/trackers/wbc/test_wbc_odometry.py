"""Leg odometry: the base follows the anchored feet, and a contact change does not make it jump."""

import numpy as np
import pytest

from g1_control.errors import WbcConfigError
from g1_control.trackers.wbc.odometry import BaseOdometry

FEET = np.array([[0.0, 0.1, 0.0], [0.0, -0.1, 0.0]])


def test_base_is_recovered_from_the_feet_even_with_a_wrong_velocity():
    odo = BaseOdometry(correction_tau_s=0.05)
    base = np.array([0.0, 0.0, 0.75])
    odo.reset(base, FEET - base)
    true_base = base.copy()
    for _ in range(500):  # the base sways 3 cm forward; the velocity estimate is biased by 0.1 m/s
        true_base[0] = min(true_base[0] + 0.001, 0.03)
        est = odo.update(0.002, np.array([0.1, 0.0, 0.0]), FEET - true_base, np.array([True, True]))
    assert est[0] == pytest.approx(0.03, abs=0.006)
    np.testing.assert_allclose(est[1:], true_base[1:], atol=1e-9)


def test_touchdown_anchors_where_the_foot_lands_without_a_jump():
    odo = BaseOdometry()
    base = np.array([0.0, 0.0, 0.75])
    odo.reset(base, FEET - base)
    # the left foot swings 0.2 m forward while the base stands on the right foot
    offsets = FEET - base
    offsets[0, 0] += 0.2
    before = odo.update(0.002, np.zeros(3), offsets, np.array([False, True])).copy()
    after = odo.update(0.002, np.zeros(3), offsets, np.array([True, True])).copy()
    np.testing.assert_allclose(after, before, atol=1e-12)
    np.testing.assert_allclose(odo.anchors_w_m[0], before + offsets[0])


def test_bad_time_constant_is_refused():
    with pytest.raises(WbcConfigError, match="correction_tau_s must be > 0"):
        BaseOdometry(0.0)


def test_touchdown_on_a_mapped_tread_anchors_the_foot_at_the_maps_height():
    # the schedule's touchdown comes with the foot 4 cm above a 0.15 m tread: the anchor takes the
    # tread's height from the map, and the base settles 4 cm lower than the foot's estimate says
    odo = BaseOdometry(correction_tau_s=0.05)
    base = np.array([0.0, 0.0, 0.75])
    odo.reset(base, FEET - base)
    offsets = FEET - base
    offsets[0] += (0.3, 0.0, 0.19)

    def tread(xy):
        return 0.15 if xy[0] > 0.2 else 0.0

    odo.update(0.002, np.zeros(3), offsets, np.array([False, True]), tread)
    for _ in range(200):
        est = odo.update(0.002, np.zeros(3), offsets, np.array([True, False]), tread)
    assert odo.anchors_w_m[0, 2] == pytest.approx(0.15)
    assert est[2] == pytest.approx(0.75 - 0.04, abs=1e-4)
    # without a map the anchor keeps the estimate's height
    plain = BaseOdometry(correction_tau_s=0.05)
    plain.reset(base, FEET - base)
    plain.update(0.002, np.zeros(3), offsets, np.array([False, True]))
    plain.update(0.002, np.zeros(3), offsets, np.array([True, False]))
    assert plain.anchors_w_m[0, 2] == pytest.approx(0.19)
