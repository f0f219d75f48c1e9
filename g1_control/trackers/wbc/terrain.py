"""What the feet stand on, for the gait: heights of the scene's platforms and steps (a map, like
the scene's other task knowledge), footholds snapped onto one tread and swing clearance.

The scene's platforms (g1_control/scene.py) are boxes standing on the floor; a stair is several of
them side by side (or one inside another), each its tread's height. The height at a point is the
highest top over it, the floor (0) elsewhere. Positions are the controller's odometry frame, which
starts at the world's origin as the scene does (the robot spawns there facing +x).

A foothold is snapped so the whole sole, with a margin, lies on one level: a sole across a tread's
edge tips over it; a higher level may not stand just ahead of its toe (the shin leans over it) nor
just behind its heel (the leg reaching down past that edge strikes it). The landing point moves along the walking heading to the nearest place where
it does (forward or back, whichever is nearer), within `max_shift_m`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from g1_control.errors import WbcConfigError
from g1_control.scene import SceneConfig


@dataclass(frozen=True)
class TerrainConfig:
    sole_half_length_m: float = 0.11
    """Half the sole's length, toe and heel pads included (contact spheres reach x -0.05..0.12 in the
    ankle-roll link, the sole frame at 0.035; plus their radius)."""
    sole_half_width_m: float = 0.04
    edge_margin_m: float = 0.025
    """A snapped sole keeps this far from a tread's edge, all round."""
    riser_gap_m: float = 0.08
    """Nothing higher than the sole may stand within this ahead of its toe: the stance shin leans
    forward over the toe as the body passes (it caught a riser's edge 3.5 cm ahead, measured). Before
    the 0.20 m platform the bent stance knee still strikes its edge while the other leg swings up
    (`g1 bench stairs --only platform`, 4 of seeds 0-4, 100-104, 200-204, 300-304). Tried, not kept
    (stop 35): nothing over 0.17 m above the sole within 0.15 m of the toe; the lead step onto the
    platform then grew to ~0.42 m: top reached 4, 5, 3, 2 of 5 on those four seed ranges against 4, 4, 3,
    4 without it, up and down 0/20 against 3/20 (measured). Since stop 47 the stance knee bends less
    there (WbcConfig.terrain_hold_pelvis_up keeps the pelvis up while the swing leg rises): the
    platform's top was reached 49 of 50 times on seeds 100-509 (35 before)."""
    drop_gap_m: float = 0.08
    """Nothing higher than the sole may stand within this behind its heel: a leg reaching down past a
    platform's edge to the floor passes that edge (landing 0.1 m beyond it, the straightened leg's knee
    struck the edge, measured: `g1 bench stairs --only platform` seed 0)."""
    max_shift_m: float = 0.25
    """Snapping moves a landing point at most this far; past it the point stays where it was."""
    shift_step_m: float = 0.01
    level_tolerance_m: float = 0.01
    """Heights within this count as one level."""

    def __post_init__(self) -> None:
        for name in ("sole_half_length_m", "sole_half_width_m", "shift_step_m"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0):
                raise WbcConfigError(f"TerrainConfig.{name} must be a finite number > 0; got {value}")
        for name in ("edge_margin_m", "riser_gap_m", "drop_gap_m", "max_shift_m", "level_tolerance_m"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value >= 0):
                raise WbcConfigError(f"TerrainConfig.{name} must be a finite number >= 0; got {value}")


class Terrain:
    """Heights of boxes standing on a flat floor at z = 0."""

    def __init__(self, blocks: list[tuple[np.ndarray, np.ndarray, float, float]] | None = None,
                 config: TerrainConfig | None = None):
        """blocks: (centre xy, half sizes xy, yaw rad, top height m) each."""
        self.config = config or TerrainConfig()
        self._centres = np.array([b[0] for b in blocks or []], dtype=float).reshape(-1, 2)
        self._halves = np.array([b[1] for b in blocks or []], dtype=float).reshape(-1, 2)
        yaws = np.array([b[2] for b in blocks or []], dtype=float)
        self._cos, self._sin = np.cos(yaws), np.sin(yaws)
        self._tops = np.array([b[3] for b in blocks or []], dtype=float)
        if np.any(self._halves <= 0) or not np.all(np.isfinite(self._tops)):
            raise WbcConfigError("Terrain blocks need half sizes > 0 and finite heights")
        c = self.config
        u = np.array([-1.0, -0.5, 0.0, 0.5, 1.0])
        gx, gy = np.meshgrid(u * (c.sole_half_length_m + c.edge_margin_m), u[::2] * (c.sole_half_width_m + c.edge_margin_m))
        self._sole_points = np.stack([gx.ravel(), gy.ravel()], axis=1)
        """Points of the sole (with its margin) in sole axes, sampled: its outline and middle."""
        gx, gy = np.meshgrid(u * c.sole_half_length_m, u[::2] * c.sole_half_width_m)
        self._bare_sole_points = np.stack([gx.ravel(), gy.ravel()], axis=1)
        """... and of the sole itself (no margin)."""
        ahead = c.sole_half_length_m + np.linspace(c.edge_margin_m, max(c.riser_gap_m, c.edge_margin_m), 4)
        gx, gy = np.meshgrid(ahead, u[::2] * (c.sole_half_width_m + c.edge_margin_m))
        self._toe_points = np.stack([gx.ravel(), gy.ravel()], axis=1)
        """Points ahead of the toe (sole axes) that may not stand higher than the sole."""
        behind = -(c.sole_half_length_m + np.linspace(c.edge_margin_m, max(c.drop_gap_m, c.edge_margin_m), 4))
        gx, gy = np.meshgrid(behind, u[::2] * (c.sole_half_width_m + c.edge_margin_m))
        self._heel_points = np.stack([gx.ravel(), gy.ravel()], axis=1)
        """Points behind the heel (sole axes) that may not stand higher than the sole."""

    @classmethod
    def of_scene(cls, scene: SceneConfig, config: TerrainConfig | None = None) -> Terrain:
        """The scene's platforms (tables are not stood on: their tops hang over one leg)."""
        return cls([(p.center, p.half, p.yaw_rad, p.height_m) for p in scene.platforms], config)

    @property
    def flat(self) -> bool:
        return self._tops.size == 0

    def heights(self, xy_m: np.ndarray) -> np.ndarray:
        """Height (m) at each of the points xy_m (n, 2): the highest top over it, else 0."""
        xy = np.asarray(xy_m, dtype=float).reshape(-1, 2)
        if self.flat:
            return np.zeros(len(xy))
        d = xy[:, None, :] - self._centres[None, :, :]
        lx = self._cos * d[..., 0] + self._sin * d[..., 1]
        ly = -self._sin * d[..., 0] + self._cos * d[..., 1]
        inside = (np.abs(lx) <= self._halves[:, 0]) & (np.abs(ly) <= self._halves[:, 1])
        return np.max(np.where(inside, self._tops, 0.0), axis=1, initial=0.0)

    def height(self, xy_m: np.ndarray) -> float:
        return float(self.heights(np.asarray(xy_m, dtype=float)[:2])[0])

    def _sole_heights(self, xy_m: np.ndarray, yaw_rad: float, points: np.ndarray | None = None) -> np.ndarray:
        c, s = math.cos(yaw_rad), math.sin(yaw_rad)
        pts = (self._sole_points if points is None else points) @ np.array([[c, s], [-s, c]])
        return self.heights(pts + np.asarray(xy_m, dtype=float)[:2])

    def sole_height(self, xy_m: np.ndarray, yaw_rad: float) -> float:
        """The highest point under a sole (with its margin) centred at xy_m, turned yaw_rad."""
        return float(self._sole_heights(xy_m, yaw_rad).max())

    def under_sole(self, xy_m: np.ndarray, yaw_rad: float) -> float:
        """The highest point under a sole itself (no margin) centred at xy_m, turned yaw_rad: where a
        foot coming down meets the terrain."""
        return float(self._sole_heights(xy_m, yaw_rad, self._bare_sole_points).max())

    def is_level(self, xy_m: np.ndarray, yaw_rad: float) -> bool:
        """Whether a sole there lies on one level, clear of its edges, of a riser ahead of it and of a
        higher level's edge behind it (TerrainConfig.riser_gap_m, drop_gap_m)."""
        return bool(self.fits_many(np.asarray(xy_m, dtype=float)[:2], yaw_rad)[0])

    def snap(self, xy_m: np.ndarray, yaw_rad: float, heading_rad: float,
             forward_only: bool = False, backward_only: bool = False,
             max_shift_m: float | None = None, level_m: float | None = None) -> tuple[np.ndarray, float]:
        """(foothold xy, its height): xy_m moved along heading_rad to the nearest place where the
        sole lies on one level (module docstring); unchanged when it does or none is in reach.
        forward_only / backward_only: only along heading_rad / only against it; max_shift_m: the
        reach (TerrainConfig.max_shift_m by default); level_m: only a place on that level (within
        level_tolerance_m) will do (`fits` tells whether the answer is one). The places are tried
        nearest first, forward before backward at the same distance (`fits` on each, evaluated for
        all of them at once: one by one, a search that found nothing cost ~6 ms a tick, measured)."""
        xy = np.asarray(xy_m, dtype=float)[:2]
        if (self.flat and level_m is None) or self.fits(xy, yaw_rad, level_m):
            return xy.copy(), self.sole_height(xy, yaw_rad)
        c = self.config
        direction = np.array([math.cos(heading_rad), math.sin(heading_rad)])
        n = int((c.max_shift_m if max_shift_m is None else max_shift_m) / c.shift_step_m)
        signs = (1.0,) if forward_only else (-1.0,) if backward_only else (1.0, -1.0)
        shifts = np.array([sign * k * c.shift_step_m for k in range(1, n + 1) for sign in signs])
        if shifts.size:
            places = xy + shifts[:, None] * direction
            ok = np.flatnonzero(self.fits_many(places, yaw_rad, level_m))
            if ok.size:
                p = places[ok[0]]
                return p, self.sole_height(p, yaw_rad)
        return xy.copy(), self.sole_height(xy, yaw_rad)

    def fits_many(self, xy_m: np.ndarray, yaw_rad: float, level_m: float | None = None) -> np.ndarray:
        """`fits` for each of the places xy_m (n, 2), soles turned yaw_rad alike: (n,) bools. A sole lies
        on one level when the heights under it (with its margin) differ by level_tolerance_m at most
        and none of the points ahead of its toe or behind its heel stands higher than it (a riser
        ahead, a higher level's edge behind); on `level_m` when its highest point is there."""
        xy = np.asarray(xy_m, dtype=float).reshape(-1, 2)
        c, s = math.cos(yaw_rad), math.sin(yaw_rad)
        rot = np.array([[c, s], [-s, c]])
        kinds = (self._sole_points, self._toe_points, self._heel_points)
        pts = np.concatenate([k @ rot for k in kinds])
        h = self.heights((xy[:, None, :] + pts[None, :, :]).reshape(-1, 2)).reshape(len(xy), -1)
        n_sole, n_toe = len(self._sole_points), len(self._toe_points)
        sole, toe, heel = h[:, :n_sole], h[:, n_sole:n_sole + n_toe], h[:, n_sole + n_toe:]
        tol = self.config.level_tolerance_m
        top = sole.max(axis=1)
        ok = (top - sole.min(axis=1) <= tol) & (toe.max(axis=1) <= top + tol) & (heel.max(axis=1) <= top + tol)
        if level_m is not None:
            ok &= np.abs(top - level_m) <= tol
        return ok

    def fits(self, xy_m: np.ndarray, yaw_rad: float, level_m: float | None = None) -> bool:
        """Whether a sole there lies on one level (is_level), and on `level_m` where given."""
        return bool(self.fits_many(np.asarray(xy_m, dtype=float)[:2], yaw_rad, level_m)[0])

    def level_change_ahead(self, xy_m: np.ndarray, heading_rad: float, distance_m: float, samples: int = 12) -> bool:
        """Whether the height changes on the straight line from xy_m distance_m along heading_rad."""
        if self.flat:
            return False
        direction = np.array([math.cos(heading_rad), math.sin(heading_rad)])
        pts = np.asarray(xy_m, dtype=float)[:2] + np.linspace(0.0, distance_m, samples)[:, None] * direction
        h = self.heights(pts)
        return bool(h.max() - h.min() > self.config.level_tolerance_m)

    def max_height_along(self, a_xy: np.ndarray, b_xy: np.ndarray, yaw_rad: float, samples: int = 8) -> float:
        """The highest point under a sole moving straight from a_xy to b_xy (clearance for a swing)."""
        if self.flat:
            return 0.0
        a, b = np.asarray(a_xy, dtype=float)[:2], np.asarray(b_xy, dtype=float)[:2]
        return max(self.sole_height(a + (b - a) * s, yaw_rad) for s in np.linspace(0.0, 1.0, samples))


__all__ = ["Terrain", "TerrainConfig"]
