"""What a replay draws besides the robot: a run's scene (tables, platforms, boxes, bottles) with its
boxes and bottles moved from the recorded ground truth, or a clip's scene shapes and handled object.

    scene = ReplayScene(scene_json=..., object_t_s=truth["t_s"], object_poses={"box": truth["box_box"]})
    spec = description.mujoco_spec(); scene.build(spec); model = spec.compile()
    scene.pose(model, data, t_s)      # before mj_forward / mj_kinematics: each moving body where it was

One form for every replay path (the headless video and PNG in sim/render.py, the MuJoCo viewer,
the browser view in sim/web.py). `arrays()` / `from_arrays()` are its form in a trajectory file:

    scene_json        a SceneConfig (g1_control/scene.py) as JSON; built by sim/scene.py
    shape_<name>      (V, 3) corners of a static convex shape, world coordinates (a clip's scene)
    mover_<name>      (V, 3) corners of a moving convex shape in its own frame (a clip's object)
    object_t_s        (N,) times of the recorded poses
    object_<name>     (N, 7) position + quaternion (w x y z) of a box or mover at those times

Drawn only: the added shapes collide with nothing (a replay sets poses, it runs no physics).
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

SHAPE_RGBA = (0.45, 0.45, 0.5, 1.0)
MOVER_RGBA = (0.9, 0.55, 0.1, 1.0)


@dataclass
class ReplayScene:
    scene_json: str = ""
    """A SceneConfig as JSON ("" for none)."""
    shapes_w_m: dict[str, np.ndarray] = field(default_factory=dict)
    """Static convex shapes: name -> (V, 3) corners in world coordinates."""
    movers_m: dict[str, np.ndarray] = field(default_factory=dict)
    """Moving convex shapes: name -> (V, 3) corners in the shape's own frame."""
    object_t_s: np.ndarray = field(default_factory=lambda: np.zeros(0))
    object_poses: dict[str, np.ndarray] = field(default_factory=dict)
    """Box or mover name -> (N, 7) position + quaternion w x y z at object_t_s."""

    @property
    def empty(self) -> bool:
        return not (self.scene_json or self.shapes_w_m or self.movers_m)

    # -- the trajectory file's keys ----------------------------------------------------------------
    def arrays(self) -> dict[str, np.ndarray]:
        out: dict[str, np.ndarray] = {}
        if self.scene_json:
            out["scene_json"] = np.asarray(self.scene_json)
        out.update({f"shape_{k}": np.asarray(v, dtype=float) for k, v in self.shapes_w_m.items()})
        out.update({f"mover_{k}": np.asarray(v, dtype=float) for k, v in self.movers_m.items()})
        if self.object_poses:
            out["object_t_s"] = np.asarray(self.object_t_s, dtype=float)
            out.update({f"object_{k}": np.asarray(v, dtype=float) for k, v in self.object_poses.items()})
        return out

    @classmethod
    def from_arrays(cls, arrays: Mapping[str, np.ndarray]) -> ReplayScene:
        def named(prefix: str) -> dict[str, np.ndarray]:
            return {k.removeprefix(prefix): np.asarray(arrays[k]) for k in arrays
                    if k.startswith(prefix) and k != "object_t_s"}

        return cls(scene_json=str(arrays["scene_json"]) if "scene_json" in arrays else "",
                   shapes_w_m=named("shape_"), movers_m=named("mover_"),
                   object_t_s=np.asarray(arrays.get("object_t_s", np.zeros(0)), dtype=float),
                   object_poses=named("object_"))

    # -- the model ----------------------------------------------------------------------------------
    def scene_config(self):
        """The SceneConfig of scene_json (None without one)."""
        if not self.scene_json:
            return None
        from g1_control.config import from_dict
        from g1_control.scene import SceneConfig

        return from_dict(SceneConfig, json.loads(self.scene_json), "scene")

    def build(self, spec) -> None:
        """Add everything to `spec` (description.mujoco_spec()), before spec.compile()."""
        import mujoco

        from g1_control.sim.scene import build_scene

        scene = self.scene_config()
        if scene is not None:
            build_scene(spec, scene)
        for name, corners in self.shapes_w_m.items():
            spec.add_mesh(name=f"shape_{name}", uservert=np.asarray(corners, dtype=float).ravel().tolist())
            spec.worldbody.add_geom(name=f"shape_{name}", type=mujoco.mjtGeom.mjGEOM_MESH, meshname=f"shape_{name}",
                                    contype=0, conaffinity=0, rgba=list(SHAPE_RGBA))
        for name, corners in self.movers_m.items():
            spec.add_mesh(name=f"mover_{name}", uservert=np.asarray(corners, dtype=float).ravel().tolist())
            body = spec.worldbody.add_body(name=name)
            body.add_freejoint(name=f"{name}_free")
            body.add_geom(name=f"{name}_geom", type=mujoco.mjtGeom.mjGEOM_MESH, meshname=f"mover_{name}",
                          contype=0, conaffinity=0, mass=1.0, rgba=list(MOVER_RGBA))

    def pose(self, model, data, t_s: float) -> None:
        """Put each recorded box or mover of `model` (built by build()) where it was at `t_s`
        (the last pose recorded at or before it)."""
        if not self.object_poses or len(self.object_t_s) == 0:
            return
        k = int(np.searchsorted(self.object_t_s, t_s, side="right") - 1)
        k = min(max(k, 0), len(self.object_t_s) - 1)
        for name, poses in self.object_poses.items():
            adr = int(model.jnt_qposadr[model.joint(f"{name}_free").id])
            data.qpos[adr:adr + 7] = poses[k]


def replay_model(scene: ReplayScene | None = None, *, video: bool = False):
    """The G1 (and `scene`) compiled for a replay. `video`: without multisampling and shadow maps,
    which in software rendering cost ~25x (1.1 s vs 0.04 s per 320x240 frame, Mesa's llvmpipe)."""
    from g1_control.robot import description

    spec = description.mujoco_spec()
    if scene is not None:
        scene.build(spec)
    model = spec.compile()
    if video:
        model.vis.quality.offsamples = 0
        model.vis.quality.shadowsize = 0
    return model


__all__ = ["ReplayScene", "replay_model"]
