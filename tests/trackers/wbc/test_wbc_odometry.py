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


def _stall_at_a_touchdown(stalled: bool) -> tuple[float, float]:
    """The base drops 2 cm while the loop stalls 130 ms; the velocity read at the stall's end (-0.25 m/s)
    says 3.25 cm. The right foot lands that tick. Returns (the right anchor's height: 0 is the truth,
    the base's height once the left foot lifts: 0.72 is the truth)."""
    odo = BaseOdometry(correction_tau_s=0.05)
    base = np.array([0.0, 0.0, 0.74])
    odo.reset(base, FEET - base)
    odo.update(0.01, np.zeros(3), FEET - base, np.array([True, False]))  # the right foot swings
    low = np.array([0.0, 0.0, 0.72])
    odo.update(0.13, np.array([0.0, 0.0, -0.25]), FEET - low, np.array([True, True]), stalled=stalled)
    anchor_z = float(odo.anchors_w_m[1, 2])
    for _ in range(20):  # the left foot lifts: the base stands on the right foot alone
        base_z = float(odo.update(0.01, np.zeros(3), FEET - low, np.array([False, True]))[2])
    return anchor_z, base_z


def test_after_a_stall_a_landing_foot_is_anchored_from_the_standing_foot():
    """stalled: corrected to the standing foot before the landing foot is anchored (0.4 cm off instead of
    1.25: the gain of one 130 ms tick, 0.72, of the 1.25 cm the velocity overshot)."""
    anchor_z, base_z = _stall_at_a_touchdown(stalled=True)
    assert abs(anchor_z) < 0.005 and abs(base_z - 0.72) < 0.005, (anchor_z, base_z)
    anchor_z, base_z = _stall_at_a_touchdown(stalled=False)  # the velocity's overshoot anchored
    assert anchor_z == pytest.approx(-0.0125, abs=1e-6) and base_z == pytest.approx(0.7075, abs=1e-3)
