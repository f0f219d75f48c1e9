"""What stands around the robot: tables, platforms (steps), boxes and bottles, in the world frame.

One description serves three readers: the simulator builds it into the MuJoCo model
(g1_control/sim/scene.py), the goal generator plans against it (where a box is, how high a table
or platform is: task knowledge, like a map), and launch files write it (`scene:`, validated like
the rest of the schema, errors naming the key). The robot starts at the origin facing +x; a launch
file may give its room in a frame of its own and say where the robot starts in it
(`scene.robot_start: {xy_m, yaw_rad}`: g1_control/launch/start_pose.py moves everything into the
start frame when the file is read).

    scene:
      tables:    [{name: table_a, center_xy_m: [2.0, 0.0], size_xy_m: [0.5, 0.8], height_m: 0.7}]
      platforms: [{name: step, center_xy_m: [1.2, 0.0], size_xy_m: [0.6, 1.0], height_m: 0.15}]
      boxes:     [{name: box, stands_on: table_a, xy_m: [1.9, 0.0], size_m: [0.3, 0.3, 0.3], mass_kg: 2.0}]
      bottles:   [{name: bottle, stands_on: table_a, xy_m: [1.8, 0.2], radius_m: 0.035, height_m: 0.2, mass_kg: 0.4}]

Nothing here imports MuJoCo; numbers are SI (m, kg, rad).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from g1_control.errors import LaunchFileError

FLOOR = "floor"
ROBOT_CLEARANCE_M = 0.35
"""Nothing may stand within this of the robot's start (the origin): it spawns there."""


def _finite(values, n: int, where: str) -> np.ndarray:
    arr = np.asarray(values, dtype=float)
    if arr.shape != (n,) or not np.all(np.isfinite(arr)):
        raise LaunchFileError(f"{where}: expected {n} finite numbers, got {values!r}")
    return arr


def _check_name(name: str, where: str) -> None:
    if not name or not name.replace("_", "").isalnum() or name != name.lower():
        raise LaunchFileError(f"{where}.name: {name!r}; names are lower case letters, digits and _")


def _rot2(yaw: float) -> np.ndarray:
    c, s = math.cos(yaw), math.sin(yaw)
    return np.array([[c, -s], [s, c]])


@dataclass
class Block:
    """A static box standing on the floor: a table top (with one central leg) or a platform."""

    name: str
    center_xy_m: tuple[float, float]
    size_xy_m: tuple[float, float]
    height_m: float
    """Top surface above the floor."""
    yaw_rad: float = 0.0
    friction: float = 1.0

    def validate(self, where: str) -> None:
        _check_name(self.name, where)
        _finite(self.center_xy_m, 2, f"{where}.center_xy_m")
        size = _finite(self.size_xy_m, 2, f"{where}.size_xy_m")
        if np.any(size <= 0.05) or np.any(size > 5.0):
            raise LaunchFileError(f"{where}.size_xy_m: {list(self.size_xy_m)} m; each side must be in (0.05, 5] m")
        if not 0.0 < self.height_m <= 1.5:
            raise LaunchFileError(f"{where}.height_m: {self.height_m} m is outside (0, 1.5] m")
        if not math.isfinite(self.yaw_rad):
            raise LaunchFileError(f"{where}.yaw_rad: must be finite, got {self.yaw_rad}")
        if not 0.05 <= self.friction <= 3.0:
            raise LaunchFileError(f"{where}.friction: {self.friction} is outside [0.05, 3]")

    @property
    def center(self) -> np.ndarray:
        return np.asarray(self.center_xy_m, dtype=float)

    @property
    def half(self) -> np.ndarray:
        return np.asarray(self.size_xy_m, dtype=float) / 2

    def local_xy(self, xy_w: np.ndarray) -> np.ndarray:
        """World xy -> this block's frame (centre, x along its first side)."""
        return _rot2(self.yaw_rad).T @ (np.asarray(xy_w, dtype=float)[:2] - self.center)

    def contains_xy(self, xy_w: np.ndarray, margin_m: float = 0.0) -> bool:
        """Whether a world point lies over the top (shrunk by margin_m on each side)."""
        p = self.local_xy(xy_w)
        return bool(np.all(np.abs(p) <= self.half - margin_m))

    def distance_xy(self, xy_w: np.ndarray) -> float:
        """Horizontal distance from a world point to the block's outline (0 inside)."""
        p = np.abs(self.local_xy(xy_w)) - self.half
        return float(np.linalg.norm(np.maximum(p, 0.0)))

    def corners_w(self) -> np.ndarray:
        h = self.half
        local = np.array([[h[0], h[1]], [-h[0], h[1]], [-h[0], -h[1]], [h[0], -h[1]]])
        return local @ _rot2(self.yaw_rad).T + self.center


@dataclass
class Table(Block):
    """A table: a top slab (4 cm) on one central leg, so feet under its edge touch nothing."""

    height_m: float = 0.7


@dataclass
class Platform(Block):
    """A solid block on the floor to step onto (a step, a stage). Its top counts as ground."""

    height_m: float = 0.15


@dataclass
class Box:
    """A free box (uniform density) resting on the floor or on a table/platform top."""

    name: str
    xy_m: tuple[float, float]
    """Centre of its footprint, world frame."""
    stands_on: str = FLOOR
    """'floor' or the name of the table/platform it stands on. (Not `on`: YAML reads that key as true.)"""
    size_m: tuple[float, float, float] = (0.3, 0.3, 0.3)
    """Extent along its own x, y, z (its x, y turned by yaw_rad)."""
    mass_kg: float = 2.0
    friction: float = 1.0
    yaw_rad: float = 0.0

    def validate(self, where: str) -> None:
        _check_name(self.name, where)
        _finite(self.xy_m, 2, f"{where}.xy_m")
        size = _finite(self.size_m, 3, f"{where}.size_m")
        if np.any(size < 0.05) or np.any(size > 0.6):
            raise LaunchFileError(f"{where}.size_m: {list(self.size_m)} m; each side must be in [0.05, 0.6] m "
                                  "(what two hands can hold)")
        if not 0.0 < self.mass_kg <= 10.0:
            raise LaunchFileError(f"{where}.mass_kg: {self.mass_kg} kg is outside (0, 10] kg")
        if not 0.05 <= self.friction <= 3.0:
            raise LaunchFileError(f"{where}.friction: {self.friction} is outside [0.05, 3]")
        if not math.isfinite(self.yaw_rad):
            raise LaunchFileError(f"{where}.yaw_rad: must be finite, got {self.yaw_rad}")

    @property
    def size(self) -> np.ndarray:
        return np.asarray(self.size_m, dtype=float)


@dataclass
class Bottle:
    """A free upright cylinder (uniform density: a bottle, a can) resting on the floor or on a
    table/platform top: what one Dex3 hand picks (generator/goals/bottle.py)."""

    name: str
    xy_m: tuple[float, float]
    """Centre of its footprint, world frame."""
    stands_on: str = FLOOR
    radius_m: float = 0.035
    height_m: float = 0.2
    mass_kg: float = 0.4
    friction: float = 1.0

    def validate(self, where: str) -> None:
        _check_name(self.name, where)
        _finite(self.xy_m, 2, f"{where}.xy_m")
        if not 0.02 <= self.radius_m <= 0.05:
            raise LaunchFileError(f"{where}.radius_m: {self.radius_m} m is outside [0.02, 0.05] m (what one Dex3 "
                                  "hand closes around)")
        if not 0.08 <= self.height_m <= 0.35:
            raise LaunchFileError(f"{where}.height_m: {self.height_m} m is outside [0.08, 0.35] m")
        if not 0.0 < self.mass_kg <= 1.5:
            raise LaunchFileError(f"{where}.mass_kg: {self.mass_kg} kg is outside (0, 1.5] kg (one hand)")
        if not 0.05 <= self.friction <= 3.0:
            raise LaunchFileError(f"{where}.friction: {self.friction} is outside [0.05, 3]")


@dataclass
class SceneConfig:
    """Objects around the robot (module docstring). Empty: the floor only, as before."""

    tables: list[Table] = field(default_factory=list)
    platforms: list[Platform] = field(default_factory=list)
    boxes: list[Box] = field(default_factory=list)
    bottles: list[Bottle] = field(default_factory=list)
    hand_collision: bool = True
    """Give the rubber hands collision boxes (the robot description has none: without them the
    hands pass through objects)."""
    grip_physics: bool = True
    """Elliptic friction cones with impratio 100, in every model the simulator builds, the bare floor
    included (MuJoCo's defaults let a squeezed box creep out of the hands at ~1 cm/s, and bound a
    foot's friction by |fx| + |fy| <= mu fz, so stance feet slid on low-friction floors; see
    g1_control/sim/scene.py and tests/sim/test_sim_floor_friction.py)."""

    def validate(self, where: str) -> None:
        names: dict[str, str] = {}
        groups: tuple[tuple[str, list[Any]], ...] = (("tables", self.tables), ("platforms", self.platforms),
                                                     ("boxes", self.boxes), ("bottles", self.bottles))  # each has a .name
        for kind, items in groups:
            for i, item in enumerate(items):
                w = f"{where}.{kind}[{i}]"
                if item.name in names or item.name == FLOOR:
                    raise LaunchFileError(f"{w}.name: '{item.name}' is already used"
                                          + (f" by {names[item.name]}" if item.name in names else " (the floor)"))
                names[item.name] = w
        for kind, blocks in (("tables", self.tables), ("platforms", self.platforms)):
            for i, b in enumerate(blocks):
                if b.distance_xy(np.zeros(2)) < ROBOT_CLEARANCE_M:
                    raise LaunchFileError(f"{where}.{kind}[{i}] ({b.name}): closer than {ROBOT_CLEARANCE_M} m to "
                                          "the robot's start at the origin")
        objects: list[tuple[str, Box | Bottle]] = [(f"{where}.boxes[{i}]", b) for i, b in enumerate(self.boxes)]
        objects += [(f"{where}.bottles[{i}]", b) for i, b in enumerate(self.bottles)]
        for w, box in objects:
            if box.stands_on != FLOOR:
                support = self.block(box.stands_on)
                if support is None:
                    raise LaunchFileError(f"{w}.stands_on: '{box.stands_on}' is not a table or platform of the scene; "
                                          f"known: {', '.join([FLOOR] + self.block_names())}")
                if not support.contains_xy(np.asarray(box.xy_m), margin_m=0.0):
                    raise LaunchFileError(f"{w}.xy_m: {list(box.xy_m)} is not over the top of '{box.stands_on}'")
            elif np.hypot(*box.xy_m) < ROBOT_CLEARANCE_M:
                raise LaunchFileError(f"{w}.xy_m: closer than {ROBOT_CLEARANCE_M} m to the robot's start")

    # -- queries ------------------------------------------------------------------------------
    @property
    def empty(self) -> bool:
        return not (self.tables or self.platforms or self.boxes or self.bottles)

    def block_names(self) -> list[str]:
        return [b.name for b in self.tables] + [b.name for b in self.platforms]

    def block(self, name: str) -> Block | None:
        for b in (*self.tables, *self.platforms):
            if b.name == name:
                return b
        return None

    def box(self, name: str) -> Box | None:
        return next((b for b in self.boxes if b.name == name), None)

    def bottle(self, name: str) -> Bottle | None:
        return next((b for b in self.bottles if b.name == name), None)

    def names(self) -> list[str]:
        return self.block_names() + [b.name for b in self.boxes] + [b.name for b in self.bottles]

    def surface_height(self, name: str) -> float:
        """Top of a table/platform, or 0 for the floor."""
        if name == FLOOR:
            return 0.0
        block = self.block(name)
        if block is None:
            raise LaunchFileError(f"'{name}' is not a table or platform; known: {', '.join(self.block_names())}")
        return block.height_m

    def box_center(self, box: Box) -> np.ndarray:
        """Where the box's centre is at the start (world, m)."""
        return np.array([box.xy_m[0], box.xy_m[1], self.surface_height(box.stands_on) + box.size[2] / 2])

    def bottle_center(self, bottle: Bottle) -> np.ndarray:
        """Where the bottle's centre is at the start (world, m)."""
        return np.array([bottle.xy_m[0], bottle.xy_m[1], self.surface_height(bottle.stands_on) + bottle.height_m / 2])

    def ground_height(self, xy_w: np.ndarray) -> float:
        """Height of what a foot stands on at xy: a platform's top, else the floor."""
        tops = [p.height_m for p in self.platforms if p.contains_xy(xy_w)]
        return max(tops, default=0.0)


__all__ = ["FLOOR", "Block", "Bottle", "Box", "Platform", "SceneConfig", "Table"]
