"""Per-frame geometry of a G1 clip, measured the way an independent checker would: the robot's
own collision geometry (robot/collision.py: the URDF's meshes as convex hulls, its foot spheres)
placed by forward kinematics of each frame's root pose and joint angles, never the clip's stored
body poses, contact labels or anything the retargeter decided.

Per frame:
- feet: the four URDF collision spheres of each foot. Each stands on the floor, or on the top of a
  scene shape under it (a top at most `near_m` above its bottom); the foot's contact sphere is the
  one nearest what it stands on (on flat ground: the lowest; on a box's edge, one over the box).
  `stance` = that sphere's bottom within `near_m` of its support and its vertical speed (from the
  previous frame) under `slow_mps`. Sliding = horizontal displacement of that sphere since the
  previous frame, on stance frames.
- penetration: the deepest any collision geometry of any link reaches below the floor (z = 0) or
  into a scene shape (coal signed distance; convex scene shapes), with the link.
- self-collision: the deepest overlap of any self-collision pair (every pair of non-adjacent links,
  CollisionModel.self_pairs), with the pair.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from g1_control.motion.clip import MotionClip
from g1_control.motion.objects import ObjectShape, support_height
from g1_control.robot import description, g1
from g1_control.robot.collision import CollisionModel, collision_model, convex_shape

NEAR_M = 0.02
"""A foot's lowest sphere this close to what it stands on is near the ground (2 cm)."""
SLOW_MPS = 0.1
"""...and in stance when it also moves vertically slower than this (0.1 m/s)."""


@dataclass
class ClipGeometry:
    fps: float
    foot_bottom_m: np.ndarray
    """(T, 2) height of the bottom of each foot's contact sphere (left, right)."""
    foot_support_m: np.ndarray
    """(T, 2) height of what that sphere stands on (floor 0 or a scene top)."""
    foot_vz_mps: np.ndarray
    """(T, 2) vertical speed of that sphere from the previous frame (0 at frame 0)."""
    foot_slide_m: np.ndarray
    """(T, 2) horizontal displacement of that sphere from the previous frame (0 at frame 0)."""
    stance: np.ndarray
    """(T, 2) near the ground and slow (frame 0: never, it has no previous frame)."""
    penetration_m: np.ndarray
    """(T,) deepest penetration of any link into the floor or a scene shape (>= 0)."""
    penetration_link: np.ndarray
    """(T,) index into `links` of the link reaching it (-1: none)."""
    self_penetration_m: np.ndarray
    """(T,) deepest overlap of a self-collision pair (>= 0)."""
    self_pair: np.ndarray
    """(T, 2) indices into `links` of that pair (-1: none)."""
    links: tuple[str, ...]


def clip_configurations(clip: MotionClip) -> np.ndarray:
    """(T, 36) pinocchio configurations of the clip's frames (root pose and joints only)."""
    quats = clip.root_quat_wxyz / np.linalg.norm(clip.root_quat_wxyz, axis=1, keepdims=True)
    return np.stack([description.pinocchio_q(p, r, j)
                     for p, r, j in zip(clip.root_pos_w_m, quats, clip.joint_pos_rad)])


def _foot_spheres(model: CollisionModel) -> list[list[int]]:
    out = []
    for foot in g1.FOOT_BODIES:
        spheres = [k for k, g in enumerate(model.geometries) if g.link == foot and g.radius_m > 0]
        if not spheres:
            raise ValueError(f"the G1 collision model has no spheres on {foot}")
        out.append(spheres)
    return out


def measure(clip: MotionClip, scene: tuple[ObjectShape, ...] | None = None, near_m: float = NEAR_M,
            slow_mps: float = SLOW_MPS) -> ClipGeometry:
    """Per-frame geometry of `clip` against `scene` (default: the clip's own scene)."""
    scene = clip.scene if scene is None else tuple(scene)
    model = collision_model()
    links = model.link_names
    link_of_geom = np.array([links.index(g.link) for g in model.geometries])
    shapes = []
    for shape in scene:
        vertices = shape.vertices()
        centre = 0.5 * (vertices.min(axis=0) + vertices.max(axis=0))
        shapes.append((convex_shape(vertices), centre, float(np.linalg.norm(vertices - centre, axis=1).max())))
    feet = _foot_spheres(model)
    t = clip.num_frames
    centres = np.empty((t, 2, max(len(f) for f in feet), 3))
    radii = np.array([[model.geometries[k].radius_m for k in f] for f in feet])
    pen = np.zeros(t)
    pen_link = np.full(t, -1)
    self_pen = np.zeros(t)
    self_pair = np.full((t, 2), -1)
    for k, q in enumerate(clip_configurations(clip)):
        model.set_configuration(q)
        depth = np.maximum(0.0, -model.lowest_points())
        for shape, centre, radius in shapes:
            depth = np.maximum(depth, -model.distances_to(shape, centre, radius))
        g = int(depth.argmax())
        if depth[g] > 0:
            pen[k], pen_link[k] = depth[g], link_of_geom[g]
        gaps = model.self_distances()
        p = int(gaps.argmin())
        if gaps[p] < 0:
            self_pen[k] = -gaps[p]
            self_pair[k] = link_of_geom[model.self_pairs[p]]
        for side, spheres in enumerate(feet):
            centres[k, side] = model.sphere_centres_w(spheres)
    bottoms = centres.copy()
    bottoms[..., 2] -= radii  # (T, 2, S, 3): each sphere's lowest point
    supports = support_height(scene, bottoms.reshape(-1, 3), 0.0, near_m).reshape(bottoms.shape[:3])
    # The foot's contact sphere: the one nearest what is under it (on flat ground, the lowest; a
    # foot on a box's edge stands on the spheres over the box, not on the one hanging past it).
    lowest = (bottoms[..., 2] - supports).argmin(axis=2)  # (T, 2)
    pick = lowest[..., None, None]
    point = np.take_along_axis(centres, pick, axis=2)[:, :, 0]  # (T, 2, 3)
    before = np.take_along_axis(np.roll(centres, 1, axis=0), pick, axis=2)[:, :, 0]
    bottom = np.take_along_axis(bottoms[..., 2], lowest[..., None], axis=2)[..., 0]
    support = np.take_along_axis(supports, lowest[..., None], axis=2)[..., 0]
    vz = np.zeros((t, 2))
    slide = np.zeros((t, 2))
    if t > 1:
        vz[1:] = (point[1:, :, 2] - before[1:, :, 2]) * clip.fps
        slide[1:] = np.linalg.norm(point[1:, :, :2] - before[1:, :, :2], axis=-1)
    stance = (np.abs(bottom - support) <= near_m) & (np.abs(vz) < slow_mps)
    stance[0] = False
    return ClipGeometry(clip.fps, bottom, support, vz, slide, stance, pen, pen_link, self_pen, self_pair, links)


@dataclass
class CrossCheck:
    """The same clip through MuJoCo's collision detection (its own convex hulls of the same meshes)."""

    self_penetration_m: np.ndarray
    """(T,) deepest robot-robot contact."""
    penetration_m: np.ndarray
    """(T,) deepest robot-floor or robot-scene contact."""


def mujoco_cross_check(clip: MotionClip, scene: tuple[ObjectShape, ...] | None = None) -> CrossCheck:
    """Per-frame depths from MuJoCo's mj_collision on a model where every collision geometry of the
    G1 collides with every other one (MuJoCo's rule: not within one body, not parent with child)."""
    import mujoco

    from g1_control.robot.collision import mujoco_collision_spec

    scene = clip.scene if scene is None else tuple(scene)
    model = mujoco_collision_spec(tuple(s.vertices() for s in scene)).compile()
    data = mujoco.MjData(model)
    world = {i for i in range(model.ngeom) if model.geom_bodyid[i] == 0}
    t = clip.num_frames
    self_pen, pen = np.zeros(t), np.zeros(t)
    joints = [model.joint(n).qposadr[0] for n in g1.JOINT_NAMES]
    for k in range(t):
        data.qpos[:3] = clip.root_pos_w_m[k]
        data.qpos[3:7] = clip.root_quat_wxyz[k] / np.linalg.norm(clip.root_quat_wxyz[k])
        data.qpos[joints] = clip.joint_pos_rad[k]
        mujoco.mj_kinematics(model, data)
        mujoco.mj_collision(model, data)
        for c in data.contact[:data.ncon]:
            depth = -float(c.dist)
            if c.geom1 in world or c.geom2 in world:
                pen[k] = max(pen[k], depth)
            else:
                self_pen[k] = max(self_pen[k], depth)
    return CrossCheck(self_pen, pen)
