"""Objects a motion interacts with (the box in OMOMO box lifting): shape, trajectory, hand contacts.

Shape: a convex polytope, the half-spaces n . x + d <= 0 (unit n, object frame, m) of the convex
hull of the object's mesh. Its signed distance is taken as max_i (n_i . x + d_i): exact inside the
object and over its faces, a slight under-estimate beside edges and corners, which is what a
"is the hand at the surface" test needs (a box's hull is the box).

Trajectory: world pose per frame (position, quaternion w x y z), at the motion's frame rate.
Hand contacts: (T, 2) labels (left, right), true where the *source* motion's hand is at the
object's surface; the retargeted clip keeps them so the metrics can check that the G1's hands are
still there on those frames (contact preservation).

Scene: static shapes in world coordinates (the boxes of the climbing sequences): the IK keeps the
feet on and above them (GroundLimit) and the metrics count penetration into them.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from g1_control import rotations as quat
from g1_control.motion.exceptions import InvalidClipError, MotionFormatError


@dataclass(frozen=True, eq=False)
class ObjectShape:
    name: str
    planes: np.ndarray
    """(F, 4) rows (nx, ny, nz, d): inside where n . x + d <= 0 for every row (object frame, m)."""

    @classmethod
    def from_points(cls, name: str, points: np.ndarray) -> ObjectShape:
        """The convex hull of mesh vertices (N, 3)."""
        from scipy.spatial import ConvexHull, QhullError

        points = np.asarray(points, dtype=float)
        if points.ndim != 2 or points.shape[1] != 3 or points.shape[0] < 4:
            raise MotionFormatError(f"object '{name}': need at least 4 vertices (N, 3); got shape {points.shape}")
        try:
            hull = ConvexHull(points)
        except QhullError as exc:
            raise MotionFormatError(f"object '{name}': vertices span no volume ({str(exc).splitlines()[0]})") from None
        return cls(name, np.array(hull.equations))  # scipy: unit normals, n . x + d <= 0 inside

    @classmethod
    def box(cls, name: str, half_extents_m: tuple[float, float, float]) -> ObjectShape:
        h = np.asarray(half_extents_m, dtype=float)
        if h.shape != (3,) or not np.all(h > 0):
            raise MotionFormatError(f"object '{name}': box half extents must be 3 positive numbers; got {half_extents_m}")
        eye = np.eye(3)
        return cls(name, np.concatenate([np.c_[eye, -h], np.c_[-eye, -h]]))

    def signed_distance(self, points_o: np.ndarray) -> np.ndarray:
        """(..., 3) points in the object frame -> (...) distance to the surface, negative inside."""
        return (points_o @ self.planes[:, :3].T + self.planes[:, 3]).max(axis=-1)

    def nearest_face(self, points_o: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(N, 3) points -> (signed distance (N,), index (N,) of the face giving it): the face to
        push a point out through, and whose normal linearises the distance."""
        values = points_o @ self.planes[:, :3].T + self.planes[:, 3]
        face = values.argmax(axis=1)
        return values[np.arange(face.shape[0]), face], face

    def scaled(self, factor: float) -> ObjectShape:
        """The shape grown by `factor` about the object origin (a human-to-robot scale)."""
        planes = self.planes.copy()
        planes[:, 3] *= factor
        return ObjectShape(self.name, planes)

    def mirrored(self) -> ObjectShape:
        """Reflected across the object's x-z plane (y -> -y)."""
        planes = self.planes.copy()
        planes[:, 1] *= -1.0
        return ObjectShape(self.name, planes)

    def top_height(self, xy: np.ndarray) -> np.ndarray:
        """(N, 2) world-aligned points -> (N,) height of the shape's upper surface above each, or
        -inf where the point is outside its footprint. For a shape whose frame is the world's (a
        static scene object): what a foot standing there rests on."""
        n, d = self.planes[:, :3], self.planes[:, 3]
        up, down, side = n[:, 2] > 1e-6, n[:, 2] < -1e-6, np.abs(n[:, 2]) <= 1e-6
        lin = xy @ n[:, :2].T + d  # (N, F): n_xy . xy + d
        top = (-lin[:, up] / n[up, 2]).min(axis=1) if up.any() else np.full(xy.shape[0], np.inf)
        bottom = (-lin[:, down] / n[down, 2]).max(axis=1) if down.any() else np.full(xy.shape[0], -np.inf)
        inside = (lin[:, side] <= 0.0).all(axis=1) & (top >= bottom)
        return np.where(inside, top, -np.inf)

    def transformed(self, rot: np.ndarray, shift_m: np.ndarray) -> ObjectShape:
        """The shape moved by x -> rot x + shift (for a static scene object in world coordinates)."""
        normals = self.planes[:, :3] @ rot.T
        return ObjectShape(self.name, np.c_[normals, self.planes[:, 3] - normals @ shift_m])

    def equals(self, other: ObjectShape) -> bool:
        return self.name == other.name and self.planes.shape == other.planes.shape and np.array_equal(
            self.planes, other.planes)


_NO_CONTACTS = np.zeros((0, 2), dtype=bool)
"""ObjectTrack.hand_contacts not given (the default): no hand at the object in any frame."""


@dataclass(eq=False)
class ObjectTrack:
    shape: ObjectShape
    pos_w_m: np.ndarray
    """(T, 3) object origin in the world."""
    quat_wxyz: np.ndarray
    """(T, 4) object orientation in the world."""
    hand_contacts: np.ndarray = field(default_factory=lambda: _NO_CONTACTS)
    """(T, 2) bool (left, right hand): the source motion's hand is at the object (default: never)."""

    def __post_init__(self) -> None:
        self.pos_w_m = np.asarray(self.pos_w_m, dtype=float)
        self.quat_wxyz = np.asarray(self.quat_wxyz, dtype=float)
        if self.hand_contacts is _NO_CONTACTS or self.hand_contacts is None:
            self.hand_contacts = np.zeros((self.pos_w_m.shape[0], 2), dtype=bool)
        self.hand_contacts = np.asarray(self.hand_contacts, dtype=bool)

    @property
    def num_frames(self) -> int:
        return int(self.pos_w_m.shape[0])

    def validate(self, num_frames: int, where: str = "") -> ObjectTrack:
        expected = {"pos_w_m": (num_frames, 3), "quat_wxyz": (num_frames, 4), "hand_contacts": (num_frames, 2)}
        for name, shape in expected.items():
            arr = getattr(self, name)
            if arr.shape != shape:
                raise InvalidClipError(f"{where or 'object'}: object {name} has shape {arr.shape}; expected {shape}")
        bad = ~np.isfinite(np.c_[self.pos_w_m, self.quat_wxyz]).all(axis=1)
        if bad.any():
            raise InvalidClipError(f"{where or 'object'}: object pose has NaN or inf at frame {int(np.flatnonzero(bad)[0])}")
        norms = np.linalg.norm(self.quat_wxyz, axis=1)
        if np.any(norms < 1e-9):
            raise InvalidClipError(f"{where or 'object'}: object quaternion is zero at frame "
                                   f"{int(np.flatnonzero(norms < 1e-9)[0])}")
        return self

    def distance(self, points_w: np.ndarray) -> np.ndarray:
        """(T, K, 3) world points -> (T, K) signed distance to the object's surface per frame."""
        rot = quat.to_matrix(self.quat_wxyz)  # (T, 3, 3)
        local = np.einsum("tji,tkj->tki", rot, points_w - self.pos_w_m[:, None, :])
        return self.shape.signed_distance(local)

    # ------------------------------------------------------------------ edits (frame-major, like MotionClip)
    def take(self, frames: np.ndarray | slice) -> ObjectTrack:
        return ObjectTrack(self.shape, self.pos_w_m[frames].copy(), self.quat_wxyz[frames].copy(),
                           self.hand_contacts[frames].copy())

    def scaled(self, factor: float) -> ObjectTrack:
        """Positions and shape scaled about the world origin (as the retargeter scales the human)."""
        return ObjectTrack(self.shape.scaled(factor), self.pos_w_m * factor, self.quat_wxyz.copy(),
                           self.hand_contacts.copy())

    def mirrored(self) -> ObjectTrack:
        """Reflected across the world x-z plane; left and right hand labels swap."""
        return ObjectTrack(self.shape.mirrored(), self.pos_w_m * np.array([1.0, -1.0, 1.0]),
                           self.quat_wxyz * np.array([1.0, -1.0, 1.0, -1.0]), self.hand_contacts[:, ::-1].copy())

    def transformed(self, rot: np.ndarray, quat_wxyz: np.ndarray, shift_m: np.ndarray) -> ObjectTrack:
        """Turned by rotation `rot` (= quaternion quat_wxyz) about the world origin, then shifted."""
        return ObjectTrack(self.shape, self.pos_w_m @ rot.T + shift_m, quat.multiply(quat_wxyz, self.quat_wxyz),
                           self.hand_contacts.copy())

    def resampled(self, fps: float, times_s: np.ndarray) -> ObjectTrack:
        from g1_control.motion.interpolation import interpolate_positions, interpolate_quaternions

        nearest = np.clip(np.rint(times_s * fps).astype(int), 0, self.num_frames - 1)
        return ObjectTrack(self.shape, interpolate_positions(self.pos_w_m, fps, times_s),
                           interpolate_quaternions(self.quat_wxyz, fps, times_s), self.hand_contacts[nearest])

    def equals(self, other: ObjectTrack | None) -> bool:
        return other is not None and self.shape.equals(other.shape) and all(
            a.shape == b.shape and np.array_equal(a, b) for a, b in (
                (self.pos_w_m, other.pos_w_m), (self.quat_wxyz, other.quat_wxyz),
                (self.hand_contacts, other.hand_contacts)))


# ---------------------------------------------------------------------------- known objects
KNOWN_OBJECTS = {"largebox": ("holosoma-demo-mocap", "holosoma_retargeting/models/largebox/largebox.obj")}
"""Object name -> (asset, mesh path inside it): shapes fetched with the data that uses them."""


def read_obj_vertices(path: str | Path) -> np.ndarray:
    """Vertex positions (N, 3) of a Wavefront OBJ file."""
    path = Path(path)
    try:
        lines = path.read_text().splitlines()
    except OSError as exc:
        raise MotionFormatError(f"{path}: cannot read the object mesh ({exc.strerror})") from None
    verts = []
    for number, line in enumerate(lines, 1):
        if line.startswith("v "):
            parts = line.split()
            try:
                verts.append([float(v) for v in parts[1:4]])
            except ValueError:
                raise MotionFormatError(f"{path}:{number}: vertex line '{line.strip()}' is not 3 numbers") from None
    return np.array(verts).reshape(-1, 3)


@functools.cache
def load_object_shape(name: str) -> ObjectShape:
    """Shape of a known object (KNOWN_OBJECTS), from its mesh in the registry asset (fetched once)."""
    from g1_control.assets import fetch

    if name not in KNOWN_OBJECTS:
        raise MotionFormatError(f"unknown object '{name}'; known: {', '.join(sorted(KNOWN_OBJECTS))}")
    asset, member = KNOWN_OBJECTS[name]
    return ObjectShape.from_points(name, read_obj_vertices(fetch(asset, quiet=True) / member))


def support_height(scene: tuple[ObjectShape, ...], points_w: np.ndarray, ground_m: float = 0.0,
                   reach_m: float = np.inf) -> np.ndarray:
    """(N, 3) points -> (N,) height of what each would stand on: the ground, or the top of a scene
    shape under it when that top is at most `reach_m` above the point (a foot beside a box, far
    below its top, is not on it)."""
    out = np.full(points_w.shape[0], float(ground_m))
    for shape in scene:
        top = shape.top_height(points_w[:, :2])
        on = np.isfinite(top) & (top <= points_w[:, 2] + reach_m)
        out = np.where(on, np.maximum(out, top), out)
    return out


def scene_depth(scene: tuple[ObjectShape, ...], points_w: np.ndarray) -> np.ndarray:
    """(..., 3) world points -> (...) deepest penetration (m, >= 0) into any scene shape."""
    depth = np.zeros(points_w.shape[:-1])
    for shape in scene:
        depth = np.maximum(depth, -shape.signed_distance(points_w))
    return depth


def load_scene(folder: str | Path) -> tuple[ObjectShape, ...]:
    """Static shapes from the OBJ meshes in `folder` (one convex shape per file, world coordinates):
    the holosoma climbing sequences' box_models/."""
    files = sorted(Path(folder).glob("*.obj"))
    return tuple(ObjectShape.from_points(f.stem, read_obj_vertices(f)) for f in files)
