"""The G1's collision geometry as its URDF states it, for checking clips and for the IK.

Every `<collision>` element of the URDF becomes one geometry: meshes as the convex hull of their
vertices (what MuJoCo collides a mesh as, so the two checkers agree), spheres and cylinders as
themselves. They sit in a pinocchio GeometryModel, so coal (hpp-fcl) gives exact signed distances
between any two of them, and between any of them and a convex scene shape (GJK, EPA when they
overlap).

Self-collision pairs: every pair of geometries on different links that are not adjacent, two
links being adjacent when one joint connects them directly (links fixed together count as one
link: the pelvis contour is the pelvis, the head and logo are the torso). A link with no collision
geometry (the waist yaw and roll links) makes its neighbours non-adjacent: the torso and the pelvis
are checked against each other. In the default pose no pair is closer than 9 mm.
"""

from __future__ import annotations

import functools
import itertools
from dataclasses import dataclass

import numpy as np

from g1_control.robot import description

CYLINDER_RIM_POINTS = 32
"""Points per cap circle that stand for a cylinder when its lowest point is wanted (error < 0.2 mm
for the G1's 3 cm shoulder cylinders)."""


@dataclass(frozen=True)
class Geometry:
    name: str
    link: str
    joint: int
    """pinocchio joint the geometry moves with."""
    points_j: np.ndarray
    """(N, 3) points whose convex hull, grown by `radius_m`, is the geometry (parent joint frame)."""
    radius_m: float
    """0 for hulls and cylinders (their points are the surface), the radius for a sphere."""
    bound_centre_j: np.ndarray
    """Centre of a sphere that holds the whole geometry (joint frame)."""
    bound_radius_m: float
    capsule_j: tuple[np.ndarray, np.ndarray, float]
    """A capsule (segment ends in the joint frame, radius) that holds the whole geometry: the IK's
    cheap first test of which pairs may be close (see bounding_capsule)."""


def bounding_capsule(points: np.ndarray, radius: float = 0.0) -> tuple[np.ndarray, np.ndarray, float]:
    """A small capsule holding every point (N, 3) grown by `radius` (so, being convex, their whole
    convex hull): axis along the points' principal direction through the middle of their spread
    across it; of the radii from the tightest possible up to 3 cm more, the one whose capsule has
    the least volume (a longer, thinner capsule or a shorter, fatter one)."""
    points = np.asarray(points, dtype=float)
    centre = points.mean(axis=0)
    if points.shape[0] == 1:
        return centre.copy(), centre.copy(), float(radius)
    _, _, axes = np.linalg.svd(points - centre, full_matrices=False)
    axis = axes[0]
    across = (points - centre) - np.outer((points - centre) @ axis, axis)
    for e in axes[1:]:  # centre the axis in the spread across it
        u = across @ e
        centre = centre + 0.5 * (u.max() + u.min()) * e
    t = (points - centre) @ axis
    perp = np.linalg.norm((points - centre) - np.outer(t, axis), axis=1)
    best: tuple[float, np.ndarray, np.ndarray, float] | None = None
    for r in np.linspace(perp.max(), perp.max() + 0.03, 31):
        half = np.sqrt(np.maximum(r * r - perp * perp, 0.0))
        t0, t1 = (t + half).min(), (t - half).max()
        if t0 > t1:  # a sphere holds them all at this radius
            t0 = t1 = 0.5 * (t0 + t1)
            r = float(np.sqrt(perp**2 + (t - t0) ** 2).max())
        volume = np.pi * r * r * (t1 - t0) + 4.0 / 3.0 * np.pi * r**3
        if best is None or volume < best[0]:
            best = (volume, centre + t0 * axis, centre + t1 * axis, float(r))
    assert best is not None  # the loop above runs at least once
    _, p0, p1, r = best
    return p0, p1, r + radius


def convex_shape(vertices: np.ndarray):
    """A coal convex shape: the convex hull of `vertices` (N, 3), in their coordinates (a mesh's
    frame, or the world for a scene shape)."""
    import coal

    vec = coal.StdVec_Vec3s()
    vec.extend(list(np.asarray(vertices, dtype=float)))
    return coal.Convex.convexHull(vec, True, "Qt")


def _shape_points(geometry, placement) -> tuple[np.ndarray, float]:
    """(points in the joint frame, radius) standing for a coal geometry placed at `placement`."""
    import coal

    rot, shift = placement.rotation, placement.translation
    if isinstance(geometry, coal.Sphere):
        return shift[None, :].copy(), float(geometry.radius)
    if isinstance(geometry, coal.Cylinder):
        angle = np.linspace(0.0, 2 * np.pi, CYLINDER_RIM_POINTS, endpoint=False)
        ring = np.c_[geometry.radius * np.cos(angle), geometry.radius * np.sin(angle), np.zeros_like(angle)]
        local = np.concatenate([ring + [0.0, 0.0, geometry.halfLength], ring - [0.0, 0.0, geometry.halfLength]])
        return local @ rot.T + shift, 0.0
    if isinstance(geometry, coal.ConvexBase):
        local = np.asarray(geometry.points())
        return local @ rot.T + shift, 0.0
    raise TypeError(f"unsupported collision geometry {type(geometry).__name__}")


class CollisionModel:
    """The G1's collision geometries and its self-collision pairs (see module docstring)."""

    def __init__(self) -> None:
        import coal
        import pinocchio as pin

        self.model = description.pinocchio_model()
        gm = pin.buildGeomFromUrdf(self.model, str(description.urdf_path()), pin.GeometryType.COLLISION,
                                   package_dirs=[str(description.description_dir().parent)])
        geometries = []
        for go in gm.geometryObjects:
            if isinstance(go.geometry, coal.BVHModelBase):
                go.geometry = convex_shape(np.asarray(go.geometry.vertices()))
            points, radius = _shape_points(go.geometry, go.placement)
            lo, hi = points.min(axis=0), points.max(axis=0)
            centre = 0.5 * (lo + hi)
            bound = float(np.linalg.norm(points - centre, axis=1).max()) + radius
            link = self.model.frames[go.parentFrame].name
            geometries.append(Geometry(go.name, link, int(go.parentJoint), points, radius, centre, bound,
                                       bounding_capsule(points, radius)))
        self.geometry_model = gm
        self.geometries: tuple[Geometry, ...] = tuple(geometries)
        self.link_names: tuple[str, ...] = tuple(dict.fromkeys(g.link for g in geometries))
        pairs = non_adjacent_pairs(self.model.parents, [g.joint for g in geometries])
        for i, k in pairs:
            gm.addCollisionPair(pin.CollisionPair(i, k))
        self.self_pairs = np.array(pairs, dtype=np.int64).reshape(-1, 2)
        """(P, 2) geometry indices of every self-collision pair (non-adjacent links)."""
        self._data = self.model.createData()
        self._geom_data = pin.GeometryData(gm)
        self._bound_centres = np.array([g.bound_centre_j for g in geometries])
        self._bound_radii = np.array([g.bound_radius_m for g in geometries])
        self._joints = [g.joint for g in geometries]
        self._request = coal.DistanceRequest()
        self._request.gjk_variant = coal.GJKVariant.NesterovAcceleration
        self._result = coal.DistanceResult()


    # ------------------------------------------------------------------ one configuration
    def set_configuration(self, q: np.ndarray) -> None:
        """Place every geometry at pinocchio configuration q (nq 36)."""
        import pinocchio as pin

        pin.forwardKinematics(self.model, self._data, q)
        pin.updateGeometryPlacements(self.model, self._data, self.geometry_model, self._geom_data)

    def _joint_poses(self) -> tuple[np.ndarray, np.ndarray]:
        omi = self._data.oMi
        rots = np.array([omi[j].rotation for j in self._joints])
        shifts = np.array([omi[j].translation for j in self._joints])
        return rots, shifts

    def bound_spheres_w(self) -> tuple[np.ndarray, np.ndarray]:
        """(G, 3) centres and (G,) radii of the geometries' bounding spheres, world."""
        rots, shifts = self._joint_poses()
        return np.einsum("gij,gj->gi", rots, self._bound_centres) + shifts, self._bound_radii

    def self_distances(self, reach_m: float = 0.05) -> np.ndarray:
        """(P,) signed distance (m; < 0: penetration depth) of every self pair at the current
        configuration. Pairs whose bounding spheres are more than `reach_m` apart get that
        (smaller than true) bounding-sphere gap instead of an exact query."""
        import pinocchio as pin

        centres, radii = self.bound_spheres_w()
        a, b = self.self_pairs[:, 0], self.self_pairs[:, 1]
        out = np.linalg.norm(centres[a] - centres[b], axis=1) - radii[a] - radii[b]
        for k in np.flatnonzero(out < reach_m):
            out[k] = pin.computeDistance(self.geometry_model, self._geom_data, int(k)).min_distance
        return out

    def distances_to(self, shape, bound_centre: np.ndarray, bound_radius: float,
                     reach_m: float = 0.05) -> np.ndarray:
        """(G,) signed distance (m) of every geometry to a coal shape fixed in the world (identity
        pose); geometries whose bounding sphere is further than `reach_m` from the shape's
        bounding sphere get that lower bound instead of an exact query."""
        import coal

        centres, radii = self.bound_spheres_w()
        out = np.linalg.norm(centres - bound_centre, axis=1) - radii - bound_radius
        identity = coal.Transform3s()
        for g in np.flatnonzero(out < reach_m):
            placement = self._geom_data.oMg[int(g)]
            self._result.clear()
            out[g] = coal.distance(self.geometry_model.geometryObjects[int(g)].geometry,
                                   coal.Transform3s(placement.rotation, placement.translation),
                                   shape, identity, self._request, self._result)
        return out

    def sphere_centres_w(self, geometry_ids: list[int]) -> np.ndarray:
        """(K, 3) world centres of sphere geometries at the current configuration."""
        omi = self._data.oMi
        out = np.empty((len(geometry_ids), 3))
        for k, g in enumerate(geometry_ids):
            pose = omi[self._joints[g]]
            out[k] = pose.rotation @ self.geometries[g].points_j[0] + pose.translation
        return out

    def lowest_points(self) -> np.ndarray:
        """(G,) height (m) of the lowest point of every geometry at the current configuration."""
        rots, shifts = self._joint_poses()
        out = np.empty(len(self.geometries))
        for g, geom in enumerate(self.geometries):
            out[g] = (geom.points_j @ rots[g][2]).min() + shifts[g][2] - geom.radius_m
        return out


def non_adjacent_pairs(parents, joints: list[int]) -> list[tuple[int, int]]:
    """Index pairs of geometries (moving with `joints`) on links that are not adjacent: not the same
    joint (one rigid link, fixed children included) and not connected by one joint."""
    def adjacent(a: int, b: int) -> bool:
        return a == b or parents[a] == b or parents[b] == a

    return [(i, k) for i, k in itertools.combinations(range(len(joints)), 2) if not adjacent(joints[i], joints[k])]


def pairs_that_can_meet(model: CollisionModel, grids: tuple[int, int, int] = (41, 41, 17),
                        clear_m: float = 0.005) -> np.ndarray:
    """(P,) bool over model.self_pairs: False for a pair that no configuration within the joint
    limits brings closer than `clear_m` (MoveIt's "never in collision"): the IK need not watch it.
    A pair whose links are joined through at most three joints depends on those joints only: its
    distance is sampled on a grid over their ranges (41 values per joint, 17 for three joints),
    then minimised from the three closest grid points (Nelder-Mead within the limits). Pairs
    further apart in the tree are kept. On the G1 this drops, among others, the wrist links
    against their neighbour but one (9.5 mm apart at rest, never closer) and the hip links against
    the other leg's."""
    import pinocchio as pin
    from scipy.optimize import minimize

    from g1_control.robot import g1

    pmodel = model.model
    data = pmodel.createData()
    keep = np.ones(len(model.self_pairs), dtype=bool)
    q0 = description.pinocchio_q(np.zeros(3), np.array([1.0, 0.0, 0.0, 0.0]), g1.DEFAULT_Q_RAD)
    for k, (a, b) in enumerate(model.self_pairs):
        ja, jb = model.geometries[a].joint, model.geometries[b].joint
        path = sorted(set(pmodel.supports[ja]) ^ set(pmodel.supports[jb]))
        if not 1 <= len(path) <= 3 or any(j < 2 for j in path):
            continue
        idx = [pmodel.joints[j].idx_q for j in path]
        lo, hi = pmodel.lowerPositionLimit[idx], pmodel.upperPositionLimit[idx]

        def distance(values: np.ndarray, k: int = k, idx: list = idx, lo=lo, hi=hi) -> float:
            q = q0.copy()
            q[idx] = np.clip(values, lo, hi)
            pin.forwardKinematics(pmodel, data, q)
            pin.updateGeometryPlacements(pmodel, data, model.geometry_model, model._geom_data)
            return pin.computeDistance(model.geometry_model, model._geom_data, k).min_distance

        grid = np.stack(np.meshgrid(*[np.linspace(lo[i], hi[i], grids[len(path) - 1]) for i in range(len(path))],
                                    indexing="ij"), axis=-1).reshape(-1, len(path))
        values = np.array([distance(v) for v in grid])
        closest = values.min()
        if closest > clear_m:
            for start in grid[np.argsort(values)[:3]]:
                closest = min(closest, minimize(distance, start, method="Nelder-Mead",
                                                options={"xatol": 1e-3, "fatol": 1e-5, "maxiter": 200}).fun)
        keep[k] = closest <= clear_m
    return keep


@functools.cache
def collision_model() -> CollisionModel:
    """The shared CollisionModel (built once per process, ~1 s: convex hulls of the meshes)."""
    return CollisionModel()


def mujoco_collision_spec(scene_vertices: tuple[np.ndarray, ...] = ()):
    """MjSpec of the G1 in which every collision geometry collides with every other and with the
    floor (MuJoCo's own rules: geometries of one body or of a parent and child body never do),
    plus static convex scene shapes given by their vertices. For cross-checking the coal checker:
    MuJoCo collides each mesh as its convex hull too."""
    import mujoco

    spec = description.mujoco_spec(floor=True)
    for geom in spec.geoms:
        if geom.group == 3 or geom.name == "floor":  # collision geometries (see description.mujoco_spec)
            geom.contype, geom.conaffinity = 1, 1
            geom.margin = 0.0
            geom.gap = 0.0
    for k, vertices in enumerate(scene_vertices):
        mesh = spec.add_mesh(name=f"scene_{k}")
        mesh.uservert = np.asarray(vertices, dtype=float).ravel().tolist()
        spec.worldbody.add_geom(name=f"scene_{k}", type=mujoco.mjtGeom.mjGEOM_MESH, meshname=f"scene_{k}",
                                contype=1, conaffinity=1)
    return spec


# ---------------------------------------------------------------------------- the IK's copy
@dataclass(frozen=True)
class StandIn:
    """One collision geometry as the IK builds it (see ik_stand_ins)."""

    name: str
    link: str
    joint: int
    placement: np.ndarray
    """(4, 4) the shape's frame in its joint's frame."""
    kind: str
    """'sphere' (params: radius), 'cylinder' (radius, half length) or 'convex' (points: its hull's vertices)."""
    points: np.ndarray
    """(K, 3) convex: hull vertices (shape frame); sphere and cylinder: empty."""
    params: tuple[float, ...]
    capsule_j: tuple[np.ndarray, np.ndarray, float]
    """A capsule (joint frame) holding the whole geometry."""

    def coal_shape(self):
        import coal

        if self.kind == "sphere":
            return coal.Sphere(self.params[0])
        if self.kind == "cylinder":
            return coal.Cylinder(self.params[0], 2.0 * self.params[1])
        return convex_shape(self.points)


def _build_stand_ins(model: CollisionModel) -> list[StandIn]:
    import coal

    out = []
    for go, geom in zip(model.geometry_model.geometryObjects, model.geometries):
        g = go.geometry
        placement = go.placement.homogeneous.copy()
        if isinstance(g, coal.Sphere):
            out.append(StandIn(geom.name, geom.link, geom.joint, placement, "sphere", np.zeros((0, 3)),
                               (float(g.radius),), geom.capsule_j))
        elif isinstance(g, coal.Cylinder):
            out.append(StandIn(geom.name, geom.link, geom.joint, placement, "cylinder", np.zeros((0, 3)),
                               (float(g.radius), float(g.halfLength)), geom.capsule_j))
        else:
            out.append(StandIn(geom.name, geom.link, geom.joint, placement, "convex", np.asarray(g.points()),
                               (0.0,), geom.capsule_j))
    return out


STAND_IN_VERSION = 3


@functools.cache
def ik_shapes() -> tuple:
    """The coal shapes of ik_stand_ins(), built once per process and shared (queries only read them)."""
    return tuple(s.coal_shape() for s in ik_stand_ins())


def ik_stand_ins() -> tuple[StandIn, ...]:
    """The collision geometries as the IK needs them: the convex hulls' vertices (not the meshes),
    placements, joints and bounding capsules. The same shapes the clip checker measures."""
    return _ik_geometry()[0]


def ik_self_pairs() -> list[tuple[int, int]]:
    """The self-collision pairs the IK keeps apart: every non-adjacent pair that can meet within
    the joint limits (pairs_that_can_meet: 530 of the 579 the checker measures)."""
    return _ik_geometry()[1]


@functools.cache
def _ik_geometry() -> tuple[tuple[StandIn, ...], list[tuple[int, int]]]:
    """Built once from the URDF (~10 s: loading 30 STL meshes and their hulls, sampling which pairs
    can meet) and kept in the user cache, keyed by the URDF's content, so that a process starting
    the IK pays ~50 ms instead."""
    import hashlib

    from g1_control.assets import cache_dir

    digest = hashlib.sha256(description.urdf_path().read_bytes()).hexdigest()[:16]
    path = cache_dir() / "collision" / f"g1_collision_v{STAND_IN_VERSION}_{digest}.npz"
    if path.is_file():
        try:
            return _load_stand_ins(path)
        except (OSError, ValueError, KeyError):
            pass  # rebuilt below
    model = collision_model()
    stand_ins = tuple(_build_stand_ins(model))
    pairs = [tuple(p) for p in model.self_pairs[pairs_that_can_meet(model)].tolist()]
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        _save_stand_ins(stand_ins, pairs, path)
    except OSError:
        pass  # a read-only cache only costs the rebuild next time
    return stand_ins, pairs


def _save_stand_ins(stand_ins: tuple[StandIn, ...], pairs: list[tuple[int, int]], path) -> None:
    arrays = {"names": np.array([s.name for s in stand_ins]), "links": np.array([s.link for s in stand_ins]),
              "joints": np.array([s.joint for s in stand_ins]), "kinds": np.array([s.kind for s in stand_ins]),
              "placements": np.array([s.placement for s in stand_ins]),
              "params": np.array([list(s.params) + [0.0] * (2 - len(s.params)) for s in stand_ins]),
              "capsules": np.array([np.r_[s.capsule_j[0], s.capsule_j[1], s.capsule_j[2]] for s in stand_ins])}
    for k, s in enumerate(stand_ins):
        arrays[f"points_{k}"] = s.points
    arrays["pairs"] = np.array(pairs, dtype=np.int64).reshape(-1, 2)
    tmp = path.with_name(path.stem + ".tmp.npz")
    np.savez(tmp, **arrays)  # type: ignore[arg-type]
    tmp.replace(path)


def _load_stand_ins(path) -> tuple[tuple[StandIn, ...], list[tuple[int, int]]]:
    with np.load(path, allow_pickle=False) as data:
        out = []
        for k, name in enumerate(data["names"]):
            kind = str(data["kinds"][k])
            count = 2 if kind == "cylinder" else 1
            cap = data["capsules"][k]
            out.append(StandIn(str(name), str(data["links"][k]), int(data["joints"][k]), data["placements"][k],
                               kind, data[f"points_{k}"], tuple(float(v) for v in data["params"][k][:count]),
                               (cap[:3].copy(), cap[3:6].copy(), float(cap[6]))))
        pairs = [tuple(p) for p in data["pairs"].tolist()]
    return tuple(out), pairs
