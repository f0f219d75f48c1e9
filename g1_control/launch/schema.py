"""The launch-file schema: one YAML per setup, validated completely before anything runs.

    g1 launch launch/sim_walk.yaml --check     # validate only
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

import yaml

from g1_control.config import from_dict
from g1_control.errors import LaunchFileError


@dataclass
class BackendConfig:
    type: Literal["mujoco"] = "mujoco"
    mode: Literal["lockstep", "wallclock"] = "lockstep"
    physics_dt_s: float = 0.002

    def validate(self, where: str) -> None:
        if not 0.0005 <= self.physics_dt_s <= 0.005:
            raise LaunchFileError(f"{where}.physics_dt_s: {self.physics_dt_s} is outside [0.0005, 0.005] s "
                                  "(physics must run at 200 Hz or faster)")


@dataclass
class RatesConfig:
    lowlevel_hz: float = 500.0
    tracker_hz: float = 50.0
    input_hz: float = 100.0
    estimator_hz: float = 100.0

    def validate(self, where: str) -> None:
        for name in ("tracker_hz", "input_hz", "estimator_hz"):
            rate = getattr(self, name)
            ratio = self.lowlevel_hz / rate if rate > 0 else 0
            if rate <= 0 or abs(ratio - round(ratio)) > 1e-9:
                raise LaunchFileError(f"{where}.{name}: {rate} Hz must divide the low-level rate "
                                      f"{self.lowlevel_hz} Hz into a whole number of ticks")


@dataclass
class TrackerConfig:
    type: Literal["policy"] = "policy"
    policy: str = "holosoma_loco_ppo"
    """Built-in spec name (g1 policies list) or a path to a spec YAML."""
    velocity_correction: bool = True


@dataclass
class GeneratorConfig:
    """Which motion generator makes the reference (g1_control/generator/factory.py)."""

    type: Literal["velocity", "backbone", "interpolation", "motion_matching"] = "velocity"
    model: str = ""
    """Backbone ONNX file; empty: the shipped policies/generator/backbone.onnx."""


@dataclass
class Segment:
    """One piece of a scripted command timeline."""

    duration_s: float
    vx_mps: float = 0.0
    vy_mps: float = 0.0
    wz_radps: float = 0.0
    label: str = ""
    style: str = "default"

    def validate(self, where: str) -> None:
        if self.duration_s <= 0:
            raise LaunchFileError(f"{where}.duration_s: must be > 0, got {self.duration_s}")


@dataclass
class RandomTimelineConfig:
    seed: int = 0
    segment_s: tuple[float, float] = (3.0, 8.0)
    vx_mps: tuple[float, float] = (-0.4, 0.8)
    vy_mps: tuple[float, float] = (-0.3, 0.3)
    wz_radps: tuple[float, float] = (-0.6, 0.6)
    stand_probability: float = 0.2


TELEOP_DEVICES = ("gamepad", "keyboard", "unitree_remote")


@dataclass
class InputConfig:
    """Where commands come from.

    scripted: `timeline` segments; random: seeded random segments; gamepad / keyboard /
    unitree_remote: a teleop device configured by `device` (path, mapping; see
    g1_control/teleop/README.md); gamepad_script: a timed gamepad sequence (`gamepad_script`)
    played through the real evdev gamepad reader, for recorded demos and tests.
    """

    type: Literal["scripted", "random", "gamepad", "keyboard", "unitree_remote", "gamepad_script"] = "scripted"
    timeline: list[Segment] = field(default_factory=list)
    random: RandomTimelineConfig = field(default_factory=RandomTimelineConfig)
    device: dict[str, Any] = field(default_factory=dict)
    fallback: Literal["keyboard"] | None = None
    """For a gamepad with path 'auto': use the keyboard when no gamepad is plugged in."""
    gamepad_script: list[dict[str, Any]] = field(default_factory=list)

    def validate(self, where: str) -> None:
        if self.type == "scripted" and not self.timeline:
            raise LaunchFileError(f"{where}.timeline: a scripted input needs at least one segment")
        if self.type == "gamepad_script":
            from g1_control.teleop.gamepad_script import parse_gamepad_script

            parse_gamepad_script(self.gamepad_script, f"{where}.gamepad_script")
        if self.type in TELEOP_DEVICES + ("gamepad_script",):
            from g1_control.teleop.layouts import LAYOUTS
            from g1_control.teleop.mapping import MappingConfig

            kind = "gamepad" if self.type == "gamepad_script" else self.type
            if "type" in self.device:
                raise LaunchFileError(f"{where}.device.type: the device type is input.type ({self.type})")
            MappingConfig.from_dict(self.device.get("mapping"), f"{where}.device.mapping", layout=LAYOUTS[kind])


@dataclass
class LimitsConfig:
    max_vx_mps: float = 1.0
    max_vy_mps: float = 0.6
    max_wz_radps: float = 1.0
    max_tilt_rad: float = 1.0
    """Beyond this pelvis tilt the robot counts as fallen and the loop damps it."""


@dataclass
class OutputConfig:
    dir: str = "runs"
    video: bool | Literal["auto"] = "auto"
    """true/false, or auto: render when headless rendering (EGL or OSMesa) works."""
    video_fps: float = 10.0
    video_size: tuple[int, int] = (480, 360)
    plot: bool = True


@dataclass
class LaunchFile:
    name: str
    duration_s: float | None = None
    """Run length; defaults to the timeline's total."""
    backend: BackendConfig = field(default_factory=BackendConfig)
    rates: RatesConfig = field(default_factory=RatesConfig)
    tracker: TrackerConfig = field(default_factory=TrackerConfig)
    generator: GeneratorConfig = field(default_factory=GeneratorConfig)
    input: InputConfig = field(default_factory=InputConfig)
    limits: LimitsConfig = field(default_factory=LimitsConfig)
    output: OutputConfig = field(default_factory=OutputConfig)
    viewer: bool | Literal["auto"] = "auto"
    """true/false, or auto: open the MuJoCo viewer when a display exists."""
    description: str = ""

    def validate(self, where: str) -> None:
        if self.duration_s is not None and self.duration_s <= 0:
            raise LaunchFileError(f"duration_s: must be > 0, got {self.duration_s}")
        lim = self.limits
        for i, seg in enumerate(self.input.timeline):
            for name, limit in (("vx_mps", lim.max_vx_mps), ("vy_mps", lim.max_vy_mps), ("wz_radps", lim.max_wz_radps)):
                value = getattr(seg, name)
                if abs(value) > limit:
                    raise LaunchFileError(f"input.timeline[{i}].{name}: {value} exceeds limits.max_{name} = {limit}")

    @property
    def total_duration_s(self) -> float:
        if self.duration_s is not None:
            return self.duration_s
        if self.input.type == "scripted":
            return sum(s.duration_s for s in self.input.timeline)
        if self.input.type == "gamepad_script" and self.input.gamepad_script:
            return float(self.input.gamepad_script[-1]["t_s"]) + 3.0
        return 60.0


def parse_launch(data, source: str = "<launch>") -> LaunchFile:
    try:
        return from_dict(LaunchFile, data, "")
    except LaunchFileError as exc:
        raise LaunchFileError(f"{source}: {exc}") from None


def load_launch(path: str | Path) -> LaunchFile:
    """Read and validate a launch file; raise LaunchFileError naming the file and key on any problem."""
    path = Path(path)
    if not path.is_file():
        raise LaunchFileError(f"{path}: no such launch file")
    try:
        data = yaml.safe_load(path.read_text())
    except yaml.YAMLError as exc:
        raise LaunchFileError(f"{path}: not valid YAML: {exc}") from None
    launch = parse_launch(data, str(path))
    # The tracker's policy must resolve and fit the robot before anything runs.
    from g1_control.trackers.policy_spec import resolve_spec_path

    try:
        resolve_spec_path(launch.tracker.policy)
    except Exception as exc:  # noqa: BLE001 - re-raised with the key path
        raise LaunchFileError(f"{path}: tracker.policy: {exc}") from None
    return launch
