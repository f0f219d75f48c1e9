"""A SceneConfig (g1_control/scene.py) built into the MuJoCo model: tables, platforms, free boxes,
collision boxes on the rubber hands and friction that holds a squeezed object.

    spec = description.mujoco_spec(timestep_s=0.002)
    build_scene(spec, scene)          # before spec.compile()

Collision classes follow the robot's (robot/description.py): robot geoms are contype 0 /
conaffinity 1 (they touch the world, not each other); static world geoms (floor, tables,
platforms) are contype 1 / conaffinity 0; a free box is 1 / 1, so it touches the robot, the world
and other boxes. Platforms are geoms of the world body itself: they are ground (a knee on a
platform is a fall, g1_control/safety/fall.py); tables are bodies of their own (a hand may touch
a table while it sets a box down).
"""

from __future__ import annotations

import mujoco
import numpy as np

from g1_control.scene import SceneConfig

WORLD_COLLISION = (1, 0)
OBJECT_COLLISION = (1, 1)
TABLE_TOP_THICKNESS_M = 0.04
TABLE_LEG_HALF_M = 0.05

# The rubber hand's extent in its body frame (right hand; the left mirrors y), from the mesh's
# vertices: x 0..0.132, y -0.019..0.048, z -0.043..0.063.
HAND_BOX_CENTER_M = np.array([0.066, 0.0145, 0.010])
HAND_BOX_HALF_M = np.array([0.066, 0.0335, 0.053])
HAND_BODIES = ("left_rubber_hand", "right_rubber_hand")
BOX_RGBA = (0.25, 0.7, 0.25, 1.0)
BOTTLE_RGBA = (0.2, 0.45, 0.85, 1.0)
"""Boxes are green: apart from the robot (grey in MuJoCo, blue in the browser), the brown tables
and the grey platforms in every video, replay and screenshot (tests look for it)."""


def _quat_z(yaw: float) -> list[float]:
    return [float(np.cos(yaw / 2)), 0.0, 0.0, float(np.sin(yaw / 2))]


def add_hand_collision(spec: mujoco.MjSpec, friction: float = 1.0) -> None:
    """A box the size of each rubber hand, colliding like the robot's other geoms."""
    for body_name, sign in zip(HAND_BODIES, (-1.0, 1.0)):
        body = spec.body(body_name)
        center = HAND_BOX_CENTER_M * np.array([1.0, sign, 1.0])
        body.add_geom(name=f"{body_name}_collision", type=mujoco.mjtGeom.mjGEOM_BOX, pos=center.tolist(),
                      size=HAND_BOX_HALF_M.tolist(), contype=0, conaffinity=1, condim=3,
                      friction=[friction, 0.005, 0.0001], group=3, rgba=[0.8, 0.8, 0.8, 0.0])


def grip_physics(spec: mujoco.MjSpec, impratio: float = 100.0) -> None:
    """Coulomb-like friction for held objects: elliptic friction cones with a high impratio.

    MuJoCo's defaults (pyramidal cones, impratio 1) let a pinched object creep and slip well inside
    the friction cone. Measured on a 2 kg box pinched between two plates (mu 1: 9.8 N per side is
    the Coulomb limit), drop over 4 s (issue 17 investigation): pyramidal cones at 30 N per side
    41 mm; elliptic cones + impratio 100 at 12-30 N 0.2 mm. It also keeps a stance foot from
    sliding off a step's edge, and from sliding on the floor: the defaults' pyramid bounds
    |fx| + |fy| <= mu fn (a diagonal push slides at 0.71 mu), and on the bare floor, which had them
    until stop 46, the model-based controller's stance feet slid at 0.1-0.3 m/s on a 0.5 friction
    floor with |f_t| / f_z ~0.3 (MuJoCo's contact forces; `g1 bench robust` draw 25 fell at 3.5 s).
    Cost: a physics step ~1.5x the defaults' (walking: 51 against 33 us, measured in one process).
    """
    spec.option.cone = mujoco.mjtCone.mjCONE_ELLIPTIC
    spec.option.impratio = impratio


def build_scene(spec: mujoco.MjSpec, scene: SceneConfig) -> None:
    """Add the scene's objects to `spec` (robot + floor from description.mujoco_spec), and its friction
    physics, an empty scene's (the bare floor) too."""
    if scene.grip_physics:
        grip_physics(spec)
    if scene.empty:
        return
    if scene.hand_collision and spec.body(HAND_BODIES[0]) is not None:  # Dex3 hands collide with their own meshes
        add_hand_collision(spec)
    world = spec.worldbody
    for t in scene.tables:
        body = world.add_body(name=t.name, pos=[*t.center_xy_m, 0.0], quat=_quat_z(t.yaw_rad))
        hx, hy = t.half
        top_z = t.height_m - TABLE_TOP_THICKNESS_M / 2
        friction = [t.friction, 0.005, 0.0001]
        body.add_geom(name=f"{t.name}_top", type=mujoco.mjtGeom.mjGEOM_BOX, pos=[0, 0, top_z],
                      size=[hx, hy, TABLE_TOP_THICKNESS_M / 2], contype=WORLD_COLLISION[0],
                      conaffinity=WORLD_COLLISION[1], condim=3, friction=friction, rgba=[0.55, 0.4, 0.25, 1.0])
        leg_h = (t.height_m - TABLE_TOP_THICKNESS_M) / 2
        body.add_geom(name=f"{t.name}_leg", type=mujoco.mjtGeom.mjGEOM_BOX, pos=[0, 0, leg_h],
                      size=[TABLE_LEG_HALF_M, TABLE_LEG_HALF_M, leg_h], contype=WORLD_COLLISION[0],
                      conaffinity=WORLD_COLLISION[1], rgba=[0.45, 0.32, 0.2, 1.0])
    for p in scene.platforms:
        hx, hy = p.half
        world.add_geom(name=p.name, type=mujoco.mjtGeom.mjGEOM_BOX, pos=[*p.center_xy_m, p.height_m / 2],
                       quat=_quat_z(p.yaw_rad), size=[hx, hy, p.height_m / 2], contype=WORLD_COLLISION[0],
                       conaffinity=WORLD_COLLISION[1], condim=3, friction=[p.friction, 0.005, 0.0001],
                       rgba=[0.45, 0.45, 0.5, 1.0])
    for b in scene.boxes:
        center = scene.box_center(b)
        body = world.add_body(name=b.name, pos=(center + [0.0, 0.0, 0.001]).tolist(), quat=_quat_z(b.yaw_rad))
        body.add_freejoint(name=f"{b.name}_free")
        body.add_geom(name=f"{b.name}_geom", type=mujoco.mjtGeom.mjGEOM_BOX, size=(b.size / 2).tolist(),
                      mass=b.mass_kg, contype=OBJECT_COLLISION[0], conaffinity=OBJECT_COLLISION[1], condim=4,
                      friction=[b.friction, 0.01, 0.0001], rgba=list(BOX_RGBA))
    add_bottles(spec, scene)


def add_bottles(spec, scene: SceneConfig) -> None:
    """The scene's bottles: free upright cylinders, each body named as the bottle (its free joint
    `<name>_free`, as a box's), colliding with the hands and what they stand on."""
    for b in scene.bottles:
        center = scene.bottle_center(b)
        body = spec.worldbody.add_body(name=b.name, pos=(center + [0.0, 0.0, 0.001]).tolist())
        body.add_freejoint(name=f"{b.name}_free")
        body.add_geom(name=f"{b.name}_geom", type=mujoco.mjtGeom.mjGEOM_CYLINDER, size=[b.radius_m, b.height_m / 2, 0.0],
                      mass=b.mass_kg, contype=OBJECT_COLLISION[0], conaffinity=OBJECT_COLLISION[1], condim=4,
                      friction=[b.friction, 0.01, 0.0001], rgba=list(BOTTLE_RGBA))


def free_body_pose(model: mujoco.MjModel, data: mujoco.MjData, name: str) -> tuple[np.ndarray, np.ndarray]:
    """(position, quaternion wxyz) of a free body (a box), from the simulator."""
    adr = int(model.jnt_qposadr[model.joint(f"{name}_free").id])
    return data.qpos[adr:adr + 3].copy(), data.qpos[adr + 3:adr + 7].copy()


__all__ = ["add_bottles", "add_hand_collision", "build_scene", "free_body_pose", "grip_physics"]
