"""What the collision limits share: pairs of the G1's own collision geometries (robot/collision.py:
the URDF's meshes as convex hulls, its foot spheres), or of one of them and a static convex shape
(the floor, a scene box), kept at least `margin_m` apart by rows on the step.

Per step: every pair's gap is first bounded from below by the geometries' bounding capsules (one
compiled pass, kernels.capsule_gaps); only pairs that may be within `activation_m` get coal's exact
signed distance (GJK, EPA when they overlap) with its witness points p_a, p_b and normal n, and a
row. With d = n . (p_b - p_a), the step must keep

    d + n^T (J_b(p_b) - J_a(p_a)) dq >= margin          (first order; kernels.witness_rows)

so the rows keep apart exactly the shapes the clip checker measures. A pair already deeper than
the margin is pushed out by at most `max_push_m` per step (asking for more could make the step
infeasible under the velocity limits). A pair a large step carries from beyond the activation
distance into the margin gets no row in that step's QP: `missed_pairs` finds it after the step, and
the retargeter solves the step again with it in `include`. Bounds and coal's answers are kept per
configuration, so a step's check of where it ended and the next step's rows share them.
"""

from __future__ import annotations

import numpy as np

from g1_control.ik import kernels
from g1_control.ik.configuration import Configuration
from g1_control.ik.exceptions import LimitDefinitionError
from g1_control.ik.limits.base import INF, Limit, RowConstraint
from g1_control.motion.objects import ObjectShape
from g1_control.robot import description
from g1_control.robot.collision import StandIn, convex_shape, ik_shapes, ik_stand_ins


class MeshPairLimit(Limit):
    def __init__(self, geometry_pairs: list[tuple[int, int]], shape_pairs: list[tuple[int, int]] | tuple[()] = (),
                 shapes: tuple[ObjectShape, ...] = (), floor_height_m: float | None = None,
                 margin_m: float = 0.002, activation_m: float = 0.03, max_push_m: float = 0.03,
                 stand_ins: tuple[StandIn, ...] | None = None) -> None:
        """geometry_pairs: (geometry, geometry) index pairs of the robot's collision geometries
        (robot.collision.ik_stand_ins: the checker's own hulls, built for the IK); shape_pairs:
        (geometry, shape) pairs, shape k < len(shapes) a scene shape (world coordinates), k ==
        len(shapes) the floor z = floor_height_m."""
        import coal
        import pinocchio as pin

        if margin_m < -0.01 or activation_m <= margin_m or max_push_m <= 0:
            raise LimitDefinitionError(f"{type(self).__name__} needs margin_m < activation_m and max_push_m > 0. "
                                       f"Got margin {margin_m} m, activation {activation_m} m, push {max_push_m} m")
        self.stand_ins = stand_ins if stand_ins is not None else ik_stand_ins()
        self.margin_m, self.activation_m, self.max_push_m = float(margin_m), float(activation_m), float(max_push_m)
        self.shapes = tuple(shapes)
        gm = pin.GeometryModel()
        shared = self.stand_ins is ik_stand_ins()
        shapes_of = ik_shapes() if shared else tuple(s.coal_shape() for s in self.stand_ins)
        for s, shape in zip(self.stand_ins, shapes_of):
            gm.addGeometryObject(pin.GeometryObject(s.name, s.joint, pin.SE3(s.placement), shape))
        planes, shape_geoms = [], []
        for shape in self.shapes:
            obj = pin.GeometryObject(f"scene_{shape.name}", 0, pin.SE3.Identity(), convex_shape(shape.vertices()))
            shape_geoms.append(gm.addGeometryObject(obj))
            planes.append(shape.planes)
        if floor_height_m is not None:
            floor = coal.Halfspace(np.array([0.0, 0.0, 1.0]), float(floor_height_m))
            shape_geoms.append(gm.addGeometryObject(pin.GeometryObject("floor", 0, pin.SE3.Identity(), floor)))
            planes.append(np.array([[0.0, 0.0, 1.0, -float(floor_height_m)]]))
        for _, k in shape_pairs:
            if not 0 <= k < len(shape_geoms):
                raise LimitDefinitionError(f"shape index {k} out of range: {len(shape_geoms)} shapes (scene + floor)")
        all_pairs = [(a, b, -1) for a, b in geometry_pairs] + [(a, shape_geoms[k], k) for a, k in shape_pairs]
        for a, b, _ in all_pairs:
            gm.addCollisionPair(pin.CollisionPair(a, b))
        self.geometry_model = gm
        self.geometry_data = pin.GeometryData(gm)
        for request in self.geometry_data.distanceRequests:
            # Nesterov-accelerated GJK: ~10x faster than the default on these 500-2000-point hulls
            # (measured: pelvis/torso 34 -> 3.7 us), same distances.
            request.gjk_variant = coal.GJKVariant.NesterovAcceleration
        self.pairs = all_pairs
        geoms = self.stand_ins
        self._geom_joint = np.array([g.joint for g in geoms], dtype=np.int64)
        self._cap_ends = np.array([[g.capsule_j[0], g.capsule_j[1]] for g in geoms])
        self._cap_radius = np.array([g.capsule_j[2] for g in geoms])
        self._pair_a = np.array([p[0] for p in all_pairs], dtype=np.int64)
        self._pair_b = np.array([p[1] if p[2] < 0 else 0 for p in all_pairs], dtype=np.int64)
        self._pair_shape = np.array([p[2] for p in all_pairs], dtype=np.int64)
        self._planes = np.concatenate(planes) if planes else np.zeros((0, 4))
        self._plane_start = np.cumsum([0] + [len(p) for p in planes]).astype(np.int64)
        pmodel = description.pinocchio_model()
        self._parents = np.array(pmodel.parents, dtype=np.int64)
        self._place_rot = np.array([pmodel.jointPlacements[k].rotation for k in range(pmodel.njoints)])
        self._place_pos = np.array([pmodel.jointPlacements[k].translation for k in range(pmodel.njoints)])
        self._axes = np.array([_revolute_axis(pmodel.joints[k].shortname()) for k in range(pmodel.njoints)],
                              dtype=np.int64)
        if pmodel.joints[1].shortname() != "JointModelFreeFlyer" or (self._axes[2:] < 0).any():
            raise LimitDefinitionError("collision limits need a free-flyer root and revolute x/y/z joints "
                                       "(kernels.joint_placements); the G1 model has other joint types")
        self._joint_rot = np.zeros((pmodel.njoints, 3, 3))
        self._joint_pos = np.zeros((pmodel.njoints, 3))
        self._ends = np.zeros((len(geoms), 2, 3))
        self._gaps = np.zeros(len(all_pairs))
        self._mask_a = self._geom_joint[self._pair_a]
        self._mask_b = np.where(self._pair_shape < 0, self._geom_joint[self._pair_b], -1)
        """Row of Configuration.joint_support_masks for each pair's a and b (b static: -1)."""
        self.include = np.zeros(len(all_pairs), dtype=bool)
        """Pairs given rows whatever their distance (see `missed_pairs`); the caller sets and clears it."""
        self._rows = np.zeros(len(all_pairs), dtype=bool)
        """Pairs the last `compute` gave rows."""
        self._version = 0
        self._inside_cache: tuple[tuple[bytes, int], tuple[np.ndarray, float]] | None = None
        self._bounds_key: bytes | None = None
        self._exact_key: bytes | None = None
        self._exact_cache: dict[int, tuple] = {}
        self.relaxed = False
        """When set, a pair inside its margin is only kept from going deeper, not pushed out (the
        retargeter's fallback when pushing out is infeasible this step)."""

    # ------------------------------------------------------------------ geometry
    def lower_bounds(self, configuration: Configuration) -> np.ndarray:
        """(P,) gap of every pair bounded from below by the bounding capsules (exact is larger)."""
        key = configuration.q.tobytes()
        if key == self._bounds_key:
            return self._gaps
        kernels.joint_placements(configuration.q, self._parents, self._place_rot, self._place_pos, self._axes,
                                 self._joint_rot, self._joint_pos)
        kernels.capsule_gaps(self._joint_rot, self._joint_pos, self._geom_joint, self._cap_ends, self._cap_radius,
                             self._pair_a, self._pair_b, self._pair_shape, self._planes, self._plane_start,
                             self._ends, self._gaps)
        self._bounds_key = key
        return self._gaps

    def exact(self, configuration: Configuration, pairs: np.ndarray
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Signed distance (K,), witness points on a and b (K, 3) and normal a -> b (K, 3) of pairs.
        Results are kept per configuration: a step's check of where it ended and the next step's
        rows, taken at the same configuration, share their queries."""
        import pinocchio as pin

        key = configuration.q.tobytes()
        if key != self._exact_key:
            self._exact_key, self._exact_cache = key, {}
            pin.updateGeometryPlacements(configuration.model, configuration.data, self.geometry_model,
                                         self.geometry_data)
        cache = self._exact_cache
        gm, gd, distance = self.geometry_model, self.geometry_data, pin.computeDistance
        wanted = np.asarray(pairs).tolist()
        for p in wanted:
            if p not in cache:
                r = distance(gm, gd, p)
                cache[p] = (r.min_distance, r.getNearestPoint1().copy(), r.getNearestPoint2().copy(), r.normal.copy())
        if not wanted:
            empty = np.zeros((0, 3))
            return np.zeros(0), empty, empty.copy(), empty.copy()
        rows = [cache[p] for p in wanted]
        return (np.array([r[0] for r in rows]), np.array([r[1] for r in rows]), np.array([r[2] for r in rows]),
                np.array([r[3] for r in rows]))

    def distances(self, configuration: Configuration) -> np.ndarray:
        """(P,) exact signed distance of every pair (slow: for tests and checks)."""
        return self.exact(configuration, np.arange(len(self.pairs)))[0]

    # ------------------------------------------------------------------ the limit
    def compute(self, configuration: Configuration, dt_s: float) -> RowConstraint | None:
        self._version += 1
        self._rows[:] = False
        if not self.pairs:
            return None
        gaps = self.lower_bounds(configuration)
        candidates = np.flatnonzero((gaps < self.activation_m) | self.include)
        if not candidates.size:
            return None
        dist, pa, pb, normal = self.exact(configuration, candidates)
        keep = (dist < self.activation_m) | self.include[candidates]
        if not keep.any():
            return None
        chosen = candidates[keep]
        self._rows[chosen] = True
        rows = np.zeros((chosen.size, configuration.nv))
        kernels.witness_rows(configuration.joint_jacobians_w, configuration.joint_support_masks(), pa[keep],
                             self._mask_a[chosen], pb[keep], self._mask_b[chosen], normal[keep], rows)
        lower = np.minimum(self.margin_m - dist[keep], 0.0 if self.relaxed else self.max_push_m)
        return RowConstraint(rows, lower, np.full(chosen.size, INF))

    def _inside(self, configuration: Configuration) -> tuple[np.ndarray, float]:
        """(pairs inside the margin (P,) bool, the smallest signed distance among them or +inf) at
        `configuration`; remembered until the configuration or the rows change (the retargeter
        asks both questions after every step)."""
        key = (configuration.q.tobytes(), self._version)
        if self._inside_cache is not None and self._inside_cache[0] == key:
            return self._inside_cache[1]
        inside = np.zeros(len(self.pairs), dtype=bool)
        deepest = float("inf")
        if self.pairs:
            candidates = np.flatnonzero(self.lower_bounds(configuration) < self.margin_m)
            if candidates.size:
                dist = self.exact(configuration, candidates)[0]
                inside[candidates] = dist < self.margin_m
                deepest = float(dist.min())
        self._inside_cache = (key, (inside, deepest))
        return inside, deepest

    def missed_pairs(self, configuration: Configuration) -> np.ndarray:
        """(P,) bool: pairs inside the margin at `configuration` that the last `compute` gave no row
        (a step carried them there from beyond the activation distance)."""
        return self._inside(configuration)[0] & ~self._rows

    def deepest(self, configuration: Configuration) -> float:
        """The smallest signed distance of any pair that may be inside the margin (else +inf)."""
        return self._inside(configuration)[1]

    def pair_names(self, k: int) -> tuple[str, str]:
        a, b, _ = self.pairs[k]
        return self.geometry_model.geometryObjects[a].name, self.geometry_model.geometryObjects[b].name


def _revolute_axis(shortname: str) -> int:
    """0, 1, 2 for pinocchio's RX, RY, RZ joints; -1 for the others (the free-flyer, the universe)."""
    return {"JointModelRX": 0, "JointModelRY": 1, "JointModelRZ": 2}.get(shortname, -1)
