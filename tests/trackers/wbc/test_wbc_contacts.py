"""Foot wrench constraints: what they admit and refuse, and their validation."""

import numpy as np
import pytest

from g1_control.errors import WbcConfigError
from g1_control.trackers.wbc.contacts import FootGeometry, cop_of, normal_force_bounds, wrench_constraint_rows


def admitted(wrench, foot=None):
    foot = foot or FootGeometry()
    C, l, u = wrench_constraint_rows(foot)
    r = C @ wrench
    return bool(np.all(r >= l - 1e-9) and np.all(r <= u + 1e-9))


def wrench_with_cop(px, py, fz=100.0, fx=0.0, fy=0.0, tz=0.0):
    return np.array([fx, fy, fz, py * fz, -px * fz, tz])


def test_cop_inside_the_usable_sole_is_admitted_and_outside_is_refused():
    foot = FootGeometry()
    assert admitted(wrench_with_cop(0.0, 0.0))
    assert admitted(wrench_with_cop(0.8 * foot.x_max_m - 1e-4, 0.8 * foot.y_min_m + 1e-4))
    assert not admitted(wrench_with_cop(0.8 * foot.x_max_m + 1e-3, 0.0))
    assert not admitted(wrench_with_cop(0.0, 0.8 * foot.y_max_m + 1e-3))
    assert not admitted(wrench_with_cop(0.8 * foot.x_min_m - 1e-3, 0.0))


def test_friction_pyramid_and_normal_force_bounds():
    mu = FootGeometry().friction
    assert admitted(wrench_with_cop(0, 0, fx=0.99 * mu * 100, fy=-0.99 * mu * 100))
    assert not admitted(wrench_with_cop(0, 0, fx=1.01 * mu * 100))
    assert not admitted(wrench_with_cop(0, 0, fy=-1.01 * mu * 100))
    assert not admitted(wrench_with_cop(0, 0, fz=-10.0))  # pulling on the floor
    assert not admitted(wrench_with_cop(0, 0, fz=100.0, tz=100.0))


def test_cop_of_recovers_the_point_and_refuses_no_load():
    np.testing.assert_allclose(cop_of(wrench_with_cop(0.03, -0.01)), [0.03, -0.01])
    with pytest.raises(WbcConfigError, match="fz = 0.0 N"):
        cop_of(np.zeros(6))


def test_normal_force_ramp_is_monotone_and_capped():
    foot = FootGeometry()
    highs = [normal_force_bounds(foot, f)[1] for f in np.linspace(0, 1, 11)]
    assert np.all(np.diff(highs) >= 0) and highs[-1] == foot.fz_max_n and highs[0] < 10.0
    assert normal_force_bounds(foot, 5.0) == normal_force_bounds(foot, 1.0)


@pytest.mark.parametrize("kwargs, text", [
    ({"x_min_m": 0.01}, "must contain the sole origin"),
    ({"cop_margin": 0.0}, "cop_margin must be in"),
    ({"friction": -1.0}, "friction must be a finite number > 0; got -1.0"),
    ({"friction": float("nan")}, "friction must be a finite number > 0; got nan"),
    ({"fz_min_n": 900.0}, "fz_min_n < fz_max_n"),
])
def test_bad_geometry_is_refused(kwargs, text):
    with pytest.raises(WbcConfigError, match=text):
        FootGeometry(**kwargs)
