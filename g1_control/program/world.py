"""The named landmarks a program refers to: objects, surfaces, platforms and points in the world frame."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from g1_control.program.exceptions import ProgramError
from g1_control.scene import SceneConfig

PLACE_KINDS = ("object", "surface", "platform", "point")
START = "start"
"""Reserved place name: where the robot stood when the program started ("walk back to the start")."""

SCENE_CLEARANCE_M = 0.3
"""World.from_scene: a walk to a table or platform stops this far outside its farthest half-extent."""

DEFAULT_STANDOFF_M = {"object": 0.45, "surface": 0.5, "platform": 0.5, "point": 0.0}
"""Where a walk to a place stops: this far from its centre (an object's is the generator's box standoff)."""


@dataclass
class Landmark:
    """A named place. pos_w_m is the centre of an object/platform/surface top, or the point itself."""

    name: str
    pos_w_m: np.ndarray
    kind: str = "object"
    standoff_m: float | None = None
    """Distance from pos_w_m where a walk to it stops; None: DEFAULT_STANDOFF_M[kind]."""

    def stop_distance_m(self) -> float:
        return DEFAULT_STANDOFF_M[self.kind] if self.standoff_m is None else float(self.standoff_m)


@dataclass
class World:
    """Named places by name (lower case, underscores: 'other_table')."""

    places: dict[str, Landmark] = field(default_factory=dict)

    @classmethod
    def of(cls, *places: Landmark) -> World:
        return cls({p.name: p for p in places}).validate()

    def names(self) -> tuple[str, ...]:
        return tuple(self.places) + (START,)

    def validate(self) -> World:
        for name, p in self.places.items():
            where = f"world.places.{name}"
            if name != p.name:
                raise ProgramError(f"{where}: key and name differ ({p.name!r})")
            if not name or " " in name or name != name.lower():
                raise ProgramError(f"{where}: a place name is lower case without spaces (e.g. 'other_table')")
            if name == START:
                raise ProgramError(f"{where}: '{START}' is reserved (where the program started)")
            pos = np.asarray(p.pos_w_m, dtype=float)
            if pos.shape != (3,) or not np.all(np.isfinite(pos)):
                raise ProgramError(f"{where}.pos_w_m: must be 3 finite numbers; got {p.pos_w_m!r}")
            p.pos_w_m = pos
            if p.kind not in PLACE_KINDS:
                raise ProgramError(f"{where}.kind: {p.kind!r} is not one of {', '.join(PLACE_KINDS)}")
            if p.standoff_m is not None and not (math.isfinite(p.standoff_m) and p.standoff_m >= 0):
                raise ProgramError(f"{where}.standoff_m: must be a finite number >= 0; got {p.standoff_m!r}")
        return self

    def __contains__(self, name: str) -> bool:
        return name in self.places or name == START

    def get(self, name: str, where: str = "world") -> Landmark:
        try:
            return self.places[name]
        except KeyError:
            raise ProgramError(f"{where}: '{name}' is not in the world; known: "
                               f"{', '.join(self.names())}") from None

    def to_dict(self) -> dict[str, Any]:
        out = {}
        for name, p in self.places.items():
            d: dict[str, Any] = {"pos_w_m": [float(v) for v in p.pos_w_m], "kind": p.kind}
            if p.standoff_m is not None:
                d["standoff_m"] = float(p.standoff_m)
            out[name] = d
        return out

    @classmethod
    def from_scene(cls, scene: SceneConfig, extra: World | None = None) -> World:
        """The scene's tables (surfaces), platforms and boxes (objects) as places, plus `extra`'s
        (named points of a launch file's input.places). A walk to a table or platform stops
        SCENE_CLEARANCE_M beyond its farthest half-extent (clear of its edge from any side)."""
        places: dict[str, Landmark] = {}
        for kind, blocks in (("surface", scene.tables), ("platform", scene.platforms)):
            for b in blocks:
                places[b.name] = Landmark(b.name, np.array([*b.center, b.height_m]), kind,
                                          float(max(b.half)) + SCENE_CLEARANCE_M)
        for box in scene.boxes:
            under = scene.block(box.stands_on)
            standoff = None  # on the floor: the object default
            if under is not None:  # on a table: stop as far from its edge as from a box on the floor
                inside = float(np.min(under.half - np.abs(under.local_xy(np.asarray(box.xy_m, dtype=float)))))
                standoff = DEFAULT_STANDOFF_M["object"] + max(0.0, inside)
            places[box.name] = Landmark(box.name, np.asarray(scene.box_center(box), dtype=float), "object", standoff)
        for name, p in (extra.places if extra is not None else {}).items():
            if name in places:
                raise ProgramError(f"world.places.{name}: the scene already has a '{name}'; name it otherwise")
            places[name] = p
        return cls(places).validate()

    @classmethod
    def from_dict(cls, data: Any) -> World:
        if not isinstance(data, dict):
            raise ProgramError(f"world: must be a mapping of place name -> {{pos_w_m, kind}}; got {data!r}")
        places = {}
        for name, d in data.items():
            if not isinstance(d, dict) or "pos_w_m" not in d:
                raise ProgramError(f"world.places.{name}: needs pos_w_m (3 numbers)")
            unknown = set(d) - {"pos_w_m", "kind", "standoff_m"}
            if unknown:
                raise ProgramError(f"world.places.{name}: unknown field(s) {sorted(unknown)}; "
                                   "known: pos_w_m, kind, standoff_m")
            places[name] = Landmark(name, np.asarray(d["pos_w_m"], dtype=float), d.get("kind", "object"),
                                 d.get("standoff_m"))
        return cls(places).validate()
