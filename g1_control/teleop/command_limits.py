"""The range of operator commands a tracker accepts.

Limits come from the tracker, not the input device: a policy was trained on a command range
and anything outside it is out of distribution. holosoma's locomotion ONNX files carry it in
their metadata as `command_ranges` = {"lin_vel_x": [-1, 1], "lin_vel_y": [-1, 1],
"ang_vel_yaw": [-1, 1], "heading": [-3.14, 3.14]} (a JSON string in the ONNX metadata map).
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from g1_control.errors import LaunchFileError
from g1_control.robot.g1 import DEFAULT_PELVIS_HEIGHT_M

# A 15 cm crouch is what the whole-body tracker was measured to follow (11 of 15 cm, docs/robot_facts.md);
# deeper crouches are untested, so the default range stops there.
DEFAULT_CROUCH_M = 0.15


def _range(value: Any, where: str) -> tuple[float, float]:
    if (
        not isinstance(value, (list, tuple))
        or len(value) != 2
        or not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in value)
    ):
        raise LaunchFileError(f"{where} is {value!r}; expected [low, high], two numbers")
    low, high = float(value[0]), float(value[1])
    if not (math.isfinite(low) and math.isfinite(high)) or low > high:
        raise LaunchFileError(f"{where} is {value!r}; expected finite low <= high")
    return low, high


@dataclass(frozen=True)
class CommandLimits:
    """Inclusive [low, high] ranges of the command fields the mapping produces."""

    vx_mps: tuple[float, float] = (-1.0, 1.0)
    vy_mps: tuple[float, float] = (-1.0, 1.0)
    wz_radps: tuple[float, float] = (-1.0, 1.0)
    pelvis_height_m: tuple[float, float] = (DEFAULT_PELVIS_HEIGHT_M - DEFAULT_CROUCH_M, DEFAULT_PELVIS_HEIGHT_M)

    def __post_init__(self) -> None:
        for name in ("vx_mps", "vy_mps", "wz_radps", "pelvis_height_m"):
            object.__setattr__(self, name, _range(getattr(self, name), f"CommandLimits.{name}"))
        for name in ("vx_mps", "vy_mps", "wz_radps"):
            low, high = getattr(self, name)
            # Zero must be reachable: releasing the sticks has to stop the robot.
            if not low <= 0.0 <= high:
                raise LaunchFileError(f"CommandLimits.{name} is {(low, high)}; the range must contain 0")

    @classmethod
    def from_tracker_metadata(cls, metadata: Mapping[str, Any], where: str = "tracker metadata") -> CommandLimits:
        """Read holosoma-style `command_ranges` (a dict, or the JSON string ONNX metadata stores).

        Fields the metadata does not name keep their defaults.
        """
        ranges = metadata.get("command_ranges")
        if ranges is None:
            raise LaunchFileError(f"{where} has no 'command_ranges'; cannot derive command limits")
        if isinstance(ranges, str):
            try:
                ranges = json.loads(ranges)
            except json.JSONDecodeError as exc:
                raise LaunchFileError(f"{where}.command_ranges is not valid JSON: {exc}") from None
        if not isinstance(ranges, Mapping):
            raise LaunchFileError(f"{where}.command_ranges is {type(ranges).__name__}; expected a mapping")
        kwargs = {}
        for key, field_name in (("lin_vel_x", "vx_mps"), ("lin_vel_y", "vy_mps"), ("ang_vel_yaw", "wz_radps")):
            if key in ranges:
                kwargs[field_name] = _range(ranges[key], f"{where}.command_ranges.{key}")
        return cls(**kwargs)

    @classmethod
    def from_dict(cls, d: Mapping[str, Any] | None, where: str) -> CommandLimits:
        """Limits written in a launch file: {vx_mps: [lo, hi], ...}; absent fields keep defaults."""
        if d is None:
            return cls()
        if not isinstance(d, Mapping):
            raise LaunchFileError(f"{where} is {type(d).__name__}; expected a mapping")
        known = ("vx_mps", "vy_mps", "wz_radps", "pelvis_height_m")
        kwargs = {}
        for key, value in d.items():
            if key not in known:
                raise LaunchFileError(f"{where}.{key} is not a command limit; known: {', '.join(known)}")
            kwargs[key] = _range(value, f"{where}.{key}")
        return cls(**kwargs)
