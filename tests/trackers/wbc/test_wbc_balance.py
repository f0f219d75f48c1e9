"""Capture-point feedback, support polygons and ZMP preview control."""

import numpy as np
import pytest

from g1_control.errors import WbcConfigError
from g1_control.generator.zmp_preview import ZmpPreviewController
from g1_control.trackers.wbc import capture_point as cp


def test_lipm_frequency_and_bad_height():
    assert cp.lipm_frequency(9.81) == pytest.approx(1.0)
    with pytest.raises(WbcConfigError, match="CoM height above 0.05 m"):
        cp.lipm_frequency(0.0)


def test_capture_point_feedback_pushes_cop_beyond_a_forward_moving_com():
    w = cp.lipm_frequency(0.65)
    zero = np.zeros(2)
    p = cp.desired_cop(zero, np.array([0.2, 0.0]), zero, zero, zero, w, gain=2.0)
    # The CoM runs forward: the CoP must go ahead of the capture point to stop it.
    xi = 0.2 / w
    assert p[0] == pytest.approx(3.0 * xi) and p[1] == 0.0
    # The resulting acceleration w^2 (c - p) decelerates the CoM
    assert w**2 * (0.0 - p[0]) < 0


def test_hull_and_projection():
    pts = np.array([[0, 0], [1, 0], [1, 1], [0, 1], [0.5, 0.5]])
    hull = cp.convex_hull(pts)
    assert len(hull) == 4
    np.testing.assert_allclose(cp.project_into_polygon(np.array([0.5, 0.5]), hull), [0.5, 0.5])
    np.testing.assert_allclose(cp.project_into_polygon(np.array([2.0, 0.5]), hull), [1.0, 0.5])
    np.testing.assert_allclose(cp.project_into_polygon(np.array([-1.0, -1.0]), hull), [0.0, 0.0])


def test_support_polygon_of_two_feet_spans_both_and_refuses_none():
    corners = np.array([[-0.1, -0.03], [0.1, -0.03], [0.1, 0.03], [-0.1, 0.03]])
    pos = np.array([[0.0, 0.1, 0.0], [0.0, -0.1, 0.0]])
    rot = np.array([np.eye(3), np.eye(3)])
    hull = cp.support_polygon(pos, rot, corners, np.array([True, True]))
    assert hull[:, 1].min() == pytest.approx(-0.13) and hull[:, 1].max() == pytest.approx(0.13)
    with pytest.raises(WbcConfigError, match="no foot in stance"):
        cp.support_polygon(pos, rot, corners, np.array([False, False]))


def test_zmp_preview_follows_a_step_in_the_zmp_reference():
    ctrl = ZmpPreviewController(0.01, 0.65)
    zmp = np.zeros((400, 1))
    zmp[150:] = 0.1
    pos, vel, acc = ctrl.plan(zmp, np.zeros(1))
    achieved = ctrl.zmp_of(pos, acc)
    assert abs(pos[-1, 0] - 0.1) < 1e-3 and abs(vel[-1, 0]) < 1e-3
    assert np.abs(achieved - zmp).max() < 0.05  # the ZMP follows the step (small overshoot)
    assert pos[140, 0] > 0.005  # preview: the CoM starts moving before the step arrives


def test_zmp_preview_refuses_bad_parameters():
    with pytest.raises(WbcConfigError, match="dt_s > 0"):
        ZmpPreviewController(0.0, 0.65)
