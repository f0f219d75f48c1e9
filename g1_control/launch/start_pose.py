"""Where the robot starts in the launch file's scene: `scene.robot_start`.

Everything the stack plans and judges with lives in the start frame: the robot starts at its origin,
facing +x, in MuJoCo (the simulator builds the scene around it) as on the robot (its estimate is
anchored where the run starts). A launch file may describe its room in a frame of its own instead (a
floor plan, motion capture's calibration) and say where the robot stands in it:

    scene:
      robot_start: {xy_m: [1.5, -0.5], yaw_rad: 1.5708}   # the robot's start in the scene's frame
      tables: [{name: t, center_xy_m: [1.5, 1.5], ...}]      # 2 m ahead of the robot

When the file is read, every position given in the scene's frame is re-expressed in the start
frame: the tables, platforms, boxes and bottles (centres and yaws), the timeline goals' `pos_w_m`, the program's
`input.places`, and an external pose with `frame: scene` (its poses are mapped on arrival, through
`estimation.external_pose.start_in_scene`). Heights are unchanged. Absent, the start is the scene's
origin and nothing moves.
"""

from __future__ import annotations

import copy
import math
from typing import Any

from g1_control.errors import LaunchFileError

KEY = "robot_start"


def _pose(value: Any) -> tuple[float, float, float]:
    where = f"scene.{KEY}"
    if not isinstance(value, dict):
        raise LaunchFileError(f"{where}: expected {{xy_m: [x, y], yaw_rad: a}} (the robot's start in the scene's "
                              f"frame), got {value!r}")
    unknown = sorted(set(value) - {"xy_m", "yaw_rad"})
    if unknown:
        raise LaunchFileError(f"{where}: unknown key(s) {', '.join(unknown)}; allowed: xy_m, yaw_rad")
    xy = value.get("xy_m", [0.0, 0.0])
    yaw = value.get("yaw_rad", 0.0)
    if (not isinstance(xy, list | tuple) or len(xy) != 2
            or not all(isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v) for v in xy)):
        raise LaunchFileError(f"{where}.xy_m: expected 2 finite numbers, got {xy!r}")
    if isinstance(yaw, bool) or not isinstance(yaw, int | float) or not math.isfinite(yaw):
        raise LaunchFileError(f"{where}.yaw_rad: expected a finite number, got {yaw!r}")
    return float(xy[0]), float(xy[1]), float(yaw)


class StartFrame:
    """Maps the scene's frame into the start frame of a robot standing at (x, y, yaw) in it."""

    def __init__(self, x: float, y: float, yaw: float):
        self.x, self.y, self.yaw = x, y, yaw
        self._c, self._s = math.cos(yaw), math.sin(yaw)

    def xy(self, xy) -> list[float]:
        dx, dy = float(xy[0]) - self.x, float(xy[1]) - self.y
        return [self._c * dx + self._s * dy, -self._s * dx + self._c * dy]

    def yaw_of(self, yaw: float) -> float:
        return math.remainder(float(yaw) - self.yaw, math.tau)


def to_start_frame(data: Any) -> Any:
    """A launch file's raw mapping with `scene.robot_start` applied (a new mapping; the input is not
    changed). Malformed positions are left for the schema to refuse, naming their keys."""
    if not isinstance(data, dict) or not isinstance(data.get("scene"), dict) or KEY not in data["scene"]:
        return data
    data = copy.deepcopy(data)
    frame = StartFrame(*_pose(data["scene"].pop(KEY)))
    scene = data["scene"]

    def move(item: Any, key: str, yaw_key: str | None) -> None:
        if not isinstance(item, dict):
            return
        value = item.get(key)
        if isinstance(value, list | tuple) and len(value) >= 2 and all(_number(v) for v in value):
            item[key] = frame.xy(value) + [float(v) for v in value[2:]]
        if yaw_key is not None:
            item[yaw_key] = frame.yaw_of(item[yaw_key]) if _number(item.get(yaw_key)) else \
                item.get(yaw_key, frame.yaw_of(0.0))

    for kind in ("tables", "platforms"):
        for block in scene.get(kind) or []:
            move(block, "center_xy_m", "yaw_rad")
    for box in scene.get("boxes") or []:
        move(box, "xy_m", "yaw_rad")
    for bottle in scene.get("bottles") or []:
        move(bottle, "xy_m", None)
    source = data.get("input")
    if isinstance(source, dict):
        for segment in source.get("timeline") or []:
            for goal in (segment.get("goals") or []) if isinstance(segment, dict) else []:
                move(goal, "pos_w_m", None)
        places = source.get("places")
        if isinstance(places, dict):
            for place in places.values():
                move(place, "pos_w_m", None)
    estimation = data.get("estimation")
    external = estimation.get("external_pose") if isinstance(estimation, dict) else None
    if isinstance(external, dict) and external.get("frame") == "scene":
        external["start_in_scene"] = [frame.x, frame.y, frame.yaw]
    return data


def _number(value: Any) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool) and math.isfinite(value)


__all__ = ["KEY", "StartFrame", "to_start_frame"]
