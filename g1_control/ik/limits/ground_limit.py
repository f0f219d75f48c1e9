"""No point of the feet below the ground: for each collision sphere of each foot (read from the
URDF, see configuration.foot_contact_points), z_centre - radius after the step >= ground height.

The ground height is a parameter (0 for a flat floor at the world origin), never a fudge offset:
a sole resting on the floor sits exactly at the ground height. Static convex scene shapes (the
boxes a climbing sequence steps onto) are kept out of too: each sphere near a shape stays outside
the face nearest to it, so a foot stands on a box's top and does not pass through its sides.
"""

from __future__ import annotations

import numpy as np

from g1_control.ik.configuration import Configuration, foot_contact_points
from g1_control.ik.limits.base import INF, Limit, RowConstraint
from g1_control.motion.objects import ObjectShape
from g1_control.robot import g1


class GroundLimit(Limit):
    def __init__(self, ground_height_m: float = 0.0, links: tuple[str, ...] = g1.FOOT_BODIES,
                 tolerance_m: float = 1e-4, scene: tuple[ObjectShape, ...] = (), reach_m: float = 0.05) -> None:
        self.ground_height_m = float(ground_height_m)
        self.scene = tuple(scene)
        """Static convex shapes (world coordinates) the foot spheres must stay out of."""
        self.reach_m = float(reach_m)
        """A sphere whose surface is within this of a scene shape gets a row for it (nearer ones only:
        far shapes cost nothing)."""
        # Slack for linearisation: a foot held level on the ground (contact equality) and these
        # rows linearise the same motion differently by ~1e-6 m; without slack the QP is infeasible.
        self.tolerance_m = float(tolerance_m)
        spheres = foot_contact_points()
        self.points: list[tuple[str, np.ndarray, float]] = [
            (link, centre, radius) for link in links for centre, radius in spheres[link]
        ]
        self._rows: RowConstraint | None = None
        self.include = np.zeros((len(self.points), len(self.scene)), dtype=bool)
        """(sphere, shape) pairs given a scene row whatever their distance (see `missed_pairs`)."""
        self._scene_rowed = np.zeros((len(self.points), len(self.scene)), dtype=bool)
        self.miss_tolerance_m = 2e-3
        """A sphere this far inside a shape after a step, with no row for it, counts as missed."""
        self.skip_links: frozenset[str] = frozenset()
        """Links whose rows are left out this step: a foot held by a ContactLimit anchored on or
        above the ground is already kept there, and its four rows would only duplicate the hold
        (degenerate active constraints that make active-set solvers fail)."""

    def _grouped(self) -> list[tuple[str, np.ndarray, np.ndarray, slice]]:
        if not hasattr(self, "_groups"):
            groups, start = [], 0
            for link in dict.fromkeys(p[0] for p in self.points):
                members = [p for p in self.points if p[0] == link]
                centres = np.array([p[1] for p in members])
                radii = np.array([p[2] for p in members])
                groups.append((link, centres, radii, slice(start, start + len(members))))
                start += len(members)
            self._groups = groups
        return self._groups

    def point_heights(self, configuration: Configuration) -> np.ndarray:
        """Height (m) of the lowest point of every sphere above the ground."""
        out = np.empty(len(self.points))
        for link, centres, radii, rows in self._grouped():
            placement = configuration.frame_placement(configuration.frame_id(link))
            out[rows] = centres @ placement.rotation[2] + placement.translation[2] - radii - self.ground_height_m
        return out

    def scene_clearances(self, configuration: Configuration) -> np.ndarray:
        """(points, shapes) distance (m) from each sphere's surface to each scene shape (< 0: inside)."""
        out = np.empty((len(self.points), len(self.scene)))
        for link, centres, radii, rows in self._grouped():
            placement = configuration.frame_placement(configuration.frame_id(link))
            world = centres @ placement.rotation.T + placement.translation
            for k, shape in enumerate(self.scene):
                out[rows, k] = shape.signed_distance(world) - radii
        return out

    def compute(self, configuration: Configuration, dt_s: float) -> RowConstraint | None:
        floor = self._floor_rows(configuration)
        if not self.scene:
            return floor
        scene = self._scene_rows(configuration)
        if scene is None or floor is None:
            return scene if floor is None else floor
        return RowConstraint(np.concatenate([floor.matrix, scene.matrix]), np.concatenate([floor.lower, scene.lower]),
                             np.concatenate([floor.upper, scene.upper]))

    def _scene_rows(self, configuration: Configuration) -> RowConstraint | None:
        """One row per (sphere, nearby shape): the sphere's centre stays at least its radius out of
        the shape, linearised on the shape's face nearest to it (the face whose plane is furthest
        from the centre; for a convex shape that plane gives the signed distance)."""
        matrices, lowers = [], []
        self._scene_rowed[:] = False
        for link, centres, radii, rows in self._grouped():
            if link in self.skip_links:
                continue
            fid = configuration.frame_id(link)
            placement = configuration.frame_placement(fid)
            arms = centres @ placement.rotation.T
            world = arms + placement.translation
            jac = None
            for k, shape in enumerate(self.scene):
                distance, face = shape.nearest_face(world)
                clearance = distance - radii
                near = np.flatnonzero((clearance < self.reach_m) | self.include[rows, k])
                if near.size == 0:
                    continue
                self._scene_rowed[rows.start + near, k] = True
                if jac is None:
                    jac = configuration.frame_jacobian(fid)
                normals = shape.planes[face[near], :3]
                # n . v_point = n . (v_origin + w x arm) = n . v_origin - (n x arm) . w
                matrices.append(normals @ jac[:3] - np.cross(normals, arms[near]) @ jac[3:])
                lowers.append(-clearance[near] - self.tolerance_m)
        if not matrices:
            return None
        lower = np.concatenate(lowers)
        return RowConstraint(np.concatenate(matrices), lower, np.full(lower.shape, INF))

    def _unskipped_clearances(self, configuration: Configuration) -> np.ndarray:
        """scene_clearances with the spheres of the skip_links feet at +inf (never inside)."""
        clear = self.scene_clearances(configuration)
        for link, _, _, rows in self._grouped():
            if link in self.skip_links:
                clear[rows] = np.inf
        return clear

    def deepest_in_scene(self, configuration: Configuration) -> float:
        """Smallest clearance (m; < 0 inside) of a sphere of a foot not in skip_links to a scene shape."""
        if not self.scene:
            return float("inf")
        return float(self._unskipped_clearances(configuration).min())

    def missed_pairs(self, configuration: Configuration) -> np.ndarray:
        """(spheres, shapes) bool: sphere-shape pairs more than miss_tolerance_m inside each other
        that the last `compute` gave no row: a step carried the foot into a box from beyond the
        rows' reach (a foot moves 10 cm and more in one tick of fast mocap). The retargeter solves
        the step again with them in `include`. Held feet (skip_links) are never missed."""
        if not self.scene:
            return self.include.copy()
        return (self._unskipped_clearances(configuration) < -self.miss_tolerance_m) & ~self._scene_rowed

    def _floor_rows(self, configuration: Configuration) -> RowConstraint | None:
        m, nv = len(self.points), configuration.nv
        if self._rows is None or self._rows.matrix.shape != (m, nv):
            self._rows = RowConstraint(np.zeros((m, nv)), np.zeros(m), np.full(m, INF))
        groups = self._grouped()
        if self.skip_links:
            groups = [g for g in groups if g[0] not in self.skip_links]
            if not groups:
                return None
            count = sum(g[3].stop - g[3].start for g in groups)
            out = RowConstraint(np.zeros((count, nv)), np.zeros(count), np.full(count, INF))
            start = 0
            for link, centres, radii, rows in groups:
                k = rows.stop - rows.start
                self._fill(configuration, link, centres, radii, out, slice(start, start + k))
                start += k
            return out
        for link, centres, radii, rows in groups:
            self._fill(configuration, link, centres, radii, self._rows, rows)
        return self._rows

    def _fill(self, configuration: Configuration, link: str, centres: np.ndarray, radii: np.ndarray,
              out: RowConstraint, rows: slice) -> None:
        fid = configuration.frame_id(link)
        placement = configuration.frame_placement(fid)
        jac = configuration.frame_jacobian(fid)
        arms = centres @ placement.rotation.T
        # z row of v_point = v_origin + w x arm: v_z + arm_y w_x - arm_x w_y
        out.matrix[rows] = jac[2] + arms[:, 1:2] * jac[3] - arms[:, 0:1] * jac[4]
        out.lower[rows] = (self.ground_height_m - self.tolerance_m + radii
                           - (arms[:, 2] + placement.translation[2]))
