"""The gait's terrain map: heights of the scene's platforms, footholds snapped onto one tread (clear
of edges and of a riser ahead), clearance over a swing's path, named configuration errors."""

import math

import numpy as np
import pytest

from g1_control.errors import WbcConfigError
from g1_control.scene import Platform, SceneConfig
from g1_control.trackers.wbc.terrain import Terrain, TerrainConfig


def stairs() -> Terrain:
    """Two 0.15 m treads, 0.4 m deep, from x = 1.0 (the upper one a platform inside the lower)."""
    return Terrain.of_scene(SceneConfig(platforms=[Platform("s1", (1.6, 0.0), (1.2, 1.2), 0.15),
                                                   Platform("s2", (1.8, 0.0), (0.8, 1.2), 0.30)]))


def test_heights_are_the_highest_top_over_a_point():
    t = stairs()
    np.testing.assert_allclose(t.heights(np.array([[0.5, 0.0], [1.1, 0.0], [1.5, 0.3], [2.3, 0.0], [1.5, 0.7]])),
                               [0.0, 0.15, 0.30, 0.0, 0.0])
    assert Terrain().flat and Terrain().height(np.array([3.0, 1.0])) == 0.0


def test_turned_platform_is_turned():
    t = Terrain.of_scene(SceneConfig(platforms=[Platform("p", (2.0, 0.0), (1.0, 0.4), 0.2, yaw_rad=math.pi / 2)]))
    assert t.height(np.array([2.0, 0.45])) == pytest.approx(0.2)  # its long side now along y
    assert t.height(np.array([2.45, 0.0])) == 0.0


def test_a_sole_across_an_edge_is_snapped_onto_one_tread_along_the_heading():
    t = stairs()
    c = t.config
    xy, h = t.snap(np.array([1.02, 0.1]), 0.0, 0.0)
    assert not t.is_level(np.array([1.02, 0.1]), 0.0)
    assert t.is_level(xy, 0.0) and xy[1] == pytest.approx(0.1)
    # the nearer of the two: forward onto the first tread, its heel clear of the edge
    assert h == pytest.approx(0.15)
    assert xy[0] - c.sole_half_length_m - c.edge_margin_m >= 1.0 - 1e-9
    assert xy[0] + c.sole_half_length_m + c.riser_gap_m <= 1.4 + 1e-9  # the riser ahead stays clear
    # well before the edge: back, the toe clear of the riser by riser_gap_m
    xy, h = t.snap(np.array([0.88, 0.0]), 0.0, 0.0)
    assert h == 0.0 and xy[0] + c.sole_half_length_m + c.riser_gap_m <= 1.0 + 1e-9
    # a level foothold is left alone
    xy, h = t.snap(np.array([1.6, 0.0]), 0.0, 0.0)
    assert xy == pytest.approx([1.6, 0.0]) and h == pytest.approx(0.30)


def test_a_foothold_snapped_onto_a_given_level():
    """level_m: only a place on that level will do (the gait's trailing foot onto the stance foot's
    tread); the nearest one along the heading, within the reach; none in reach: unchanged, and `fits`
    says it is not one."""
    t = stairs()
    c = t.config
    # on the first tread, asked for the first tread: left alone; asked for the second: forward onto it
    xy, h = t.snap(np.array([1.2, 0.0]), 0.0, 0.0, level_m=0.15)
    assert xy == pytest.approx([1.2, 0.0]) and h == pytest.approx(0.15)
    xy, h = t.snap(np.array([1.2, 0.0]), 0.0, 0.0, max_shift_m=0.45, level_m=0.30)
    assert h == pytest.approx(0.30) and t.fits(xy, 0.0, 0.30)
    assert xy[0] - c.sole_half_length_m - c.edge_margin_m >= 1.4 - 1e-9
    # on the second tread, asked for the first: back, whole sole on it
    xy, h = t.snap(np.array([1.6, 0.0]), 0.0, 0.0, max_shift_m=0.45, level_m=0.15)
    assert h == pytest.approx(0.15) and t.fits(xy, 0.0, 0.15) and xy[0] < 1.4
    # the floor out of reach: unchanged, not a fit
    xy, h = t.snap(np.array([1.6, 0.0]), 0.0, 0.0, max_shift_m=0.1, level_m=0.0)
    assert xy == pytest.approx([1.6, 0.0]) and not t.fits(xy, 0.0, 0.0)
    # without level_m, `fits` is is_level
    assert t.fits(np.array([1.6, 0.0]), 0.0) and not t.fits(np.array([1.02, 0.0]), 0.0)


def _turned_stairs() -> Terrain:
    """Three treads turned 0.3 rad, the top one wide (`g1 bench stairs`' shape)."""
    return Terrain.of_scene(SceneConfig(platforms=[
        Platform("a", (1.225, 0.0), (0.45, 1.4), 0.15, yaw_rad=0.3),
        Platform("b", (1.675, 0.1), (0.45, 1.4), 0.30, yaw_rad=0.3),
        Platform("c", (2.5, 0.2), (1.2, 1.4), 0.45, yaw_rad=0.3)]))


def test_fits_many_is_fits_at_each_place():
    """Many places at once answer as each alone (is_level and fits ask fits_many for one place)."""
    t = _turned_stairs()
    rng = np.random.default_rng(5)
    for level in (None, 0.0, 0.15, 0.30, 0.45):
        places = rng.uniform([0.5, -1.0], [3.2, 1.0], size=(300, 2))
        yaw = float(rng.uniform(-0.6, 0.6))
        assert t.fits_many(places, yaw, level).tolist() == [t.fits(p, yaw, level) for p in places]
        assert any(t.fits(p, yaw, level) for p in places) and not all(t.fits(p, yaw, level) for p in places)


def test_snap_takes_the_nearest_place_that_fits_forward_first():
    """Terrain.snap against a search one place at a time (`fits`), nearest first and forward before
    backward at the same distance, on seeded draws of place, yaw, heading, reach, level and direction."""
    t = _turned_stairs()
    step = t.config.shift_step_m
    rng = np.random.default_rng(6)
    moved = 0
    for i in range(400):
        xy = rng.uniform([0.5, -1.0], [3.2, 1.0])
        yaw, heading = (float(v) for v in rng.uniform(-0.6, 0.6, size=2))
        forward, backward = i % 5 == 1, i % 5 == 2
        reach = [None, 0.45, 0.1][i % 3]
        level = [None, 0.0, 0.15, 0.30][i % 4]
        got, height = t.snap(xy, yaw, heading, forward_only=forward, backward_only=backward, max_shift_m=reach,
                             level_m=level)
        want = xy
        if not t.fits(xy, yaw, level):
            n = int((t.config.max_shift_m if reach is None else reach) / step)
            signs = (1.0,) if forward else (-1.0,) if backward else (1.0, -1.0)
            direction = np.array([math.cos(heading), math.sin(heading)])
            want = next((xy + s * k * step * direction for k in range(1, n + 1) for s in signs
                         if t.fits(xy + s * k * step * direction, yaw, level)), xy)
        moved += not np.array_equal(want, xy)
        np.testing.assert_allclose(got, want, atol=1e-12)
        assert height == pytest.approx(t.sole_height(want, yaw))
    assert moved > 40
    # at the same distance both ways (17 steps back onto the floor, 17 on onto the tread): forward
    xy = np.array([0.972, 0.0])
    s = stairs()
    assert s.fits(xy - np.array([17 * step, 0.0]), 0.0) and s.fits(xy + np.array([17 * step, 0.0]), 0.0)
    assert s.snap(xy, 0.0, 0.0)[0] == pytest.approx([0.972 + 17 * step, 0.0])


def test_under_a_sole_is_the_highest_point_under_the_sole_itself():
    """Where a foot coming down meets the terrain: the sole's own outline, not its margin."""
    t = stairs()
    c = t.config
    # the toe over the first tread's edge: it meets the tread
    assert t.under_sole(np.array([1.0 - c.sole_half_length_m + 0.01, 0.0]), 0.0) == pytest.approx(0.15)
    # the toe short of the edge by less than the margin: the floor (sole_height, with the margin, reads the tread)
    xy = np.array([1.0 - c.sole_half_length_m - 0.01, 0.0])
    assert t.under_sole(xy, 0.0) == 0.0 and t.sole_height(xy, 0.0) == pytest.approx(0.15)
    assert Terrain().under_sole(np.array([3.0, 1.0]), 0.3) == 0.0


def test_a_riser_close_ahead_of_the_toe_is_not_level_but_an_edge_behind_the_heel_going_down_is():
    t = stairs()
    c = t.config
    toe_gap = 0.05  # < riser_gap_m
    assert not t.is_level(np.array([1.0 - c.sole_half_length_m - toe_gap, 0.0]), 0.0)
    # walking down (facing -x) a lower tread ahead of the toe is fine
    assert t.is_level(np.array([1.0 + c.sole_half_length_m + c.edge_margin_m + 0.01, 0.0]), math.pi)


def test_a_sole_stepping_down_off_an_edge_keeps_its_heel_clear_of_it():
    """Walking down off the first tread (facing -x) onto the floor: a sole whose heel lies within
    drop_gap_m of the tread's edge is not level (the leg reaching down would strike the edge)."""
    t = stairs()
    c = t.config
    close = 1.0 - c.sole_half_length_m - c.edge_margin_m - 0.01
    assert t.height(np.array([close, 0.0])) == 0.0 and not t.is_level(np.array([close, 0.0]), math.pi)
    clear = 1.0 - c.sole_half_length_m - c.drop_gap_m - 0.01
    assert t.is_level(np.array([clear, 0.0]), math.pi)
    xy, height = t.snap(np.array([close, 0.0]), math.pi, math.pi)  # walking on: the landing moves away from it
    assert height == 0.0 and xy[0] <= clear + c.shift_step_m


def test_clearance_along_a_swing_path_sees_the_tread_in_between():
    t = stairs()
    assert t.max_height_along(np.array([0.8, 0.0]), np.array([1.5, 0.0]), 0.0) == pytest.approx(0.30)
    assert t.max_height_along(np.array([0.2, 0.0]), np.array([0.6, 0.0]), 0.0) == 0.0


def test_named_errors():
    with pytest.raises(WbcConfigError, match="TerrainConfig.sole_half_length_m must be a finite number > 0"):
        TerrainConfig(sole_half_length_m=0.0)
    with pytest.raises(WbcConfigError, match="TerrainConfig.riser_gap_m must be a finite number >= 0"):
        TerrainConfig(riser_gap_m=-0.1)
    with pytest.raises(WbcConfigError, match="TerrainConfig.drop_gap_m must be a finite number >= 0"):
        TerrainConfig(drop_gap_m=-0.1)
    with pytest.raises(WbcConfigError, match="half sizes > 0"):
        Terrain([(np.zeros(2), np.array([0.0, 0.3]), 0.0, 0.1)])
