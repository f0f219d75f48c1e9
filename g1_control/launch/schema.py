"""The launch-file schema: one YAML per setup, validated completely before anything runs.

    g1 launch launch/sim_walk.yaml --check     # validate only
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

import yaml

from g1_control.config import from_dict
from g1_control.errors import LaunchFileError, SafetyConfigError
from g1_control.loop.rates import LoopRates
from g1_control.safety.config import SafetyConfig
from g1_control.teleop.scripted import RandomTimelineConfig, Segment

ROBOT_BACKENDS = ("unitree_dds", "can", "serial")
"""Backends that drive a robot (real, or `g1 sim-robot`) through a robot link; `g1 deploy` runs them."""

VARIANT_NAMES = ("g1_23dof", "g1_29dof", "g1_29dof_locked_waist")

MIN_WBC_TRACKER_HZ = 200.0
"""The whole-body controller's slowest useful rate."""


@dataclass
class BackendConfig:
    """mujoco: the simulator (g1 launch). unitree_dds / can / serial: a robot link (g1 deploy).

    unitree_dds needs `interface` (the NIC cabled to the robot, or `lo` for `g1 sim-robot`) and
    `domain` (0 on the robot, 1 in simulation); `partition` only isolates concurrent runs on one
    host. can needs `can_interface` + `channel` (python-can: socketcan/can0, virtual/NAME); serial
    needs `port` (+ `baudrate`). `expected_variant` is the G1 the launch file is written for: a
    robot reporting another mode_machine is refused.
    """

    type: Literal["mujoco", "unitree_dds", "can", "serial"] = "mujoco"
    mode: Literal["lockstep", "wallclock"] = "lockstep"
    physics_dt_s: float = 0.002
    interface: str | None = None
    domain: int = 0
    partition: str | None = None
    release_motion_service: bool = True
    """Release the robot's built-in controller first (false: the operator used the remote's debug mode)."""
    expected_variant: Literal["g1_23dof", "g1_29dof", "g1_29dof_locked_waist"] = "g1_29dof"
    hands: Literal["none", "dex3"] = "none"
    """Dex3-1 hands on the robot (g1_29dof only): the generator then plans the fingers too."""
    connect_timeout_s: float = 3.0
    command_rate_hz: float = 500.0
    mode_pr: int = 0
    can_interface: str | None = None
    channel: str | None = None
    can_fd: bool = True
    port: str | None = None
    baudrate: int = 921600

    def validate(self, where: str) -> None:
        if not 0.0005 <= self.physics_dt_s <= 0.005:
            raise LaunchFileError(f"{where}.physics_dt_s: {self.physics_dt_s} is outside [0.0005, 0.005] s "
                                  "(physics must run at 200 Hz or faster)")
        if self.type == "mujoco":
            return
        if self.type == "unitree_dds":
            if not self.interface:
                raise LaunchFileError(f"{where}.interface: a unitree_dds backend must name its network interface "
                                      "(the NIC on 192.168.123.0/24 for the robot, 'lo' for g1 sim-robot)")
            if not 0 <= self.domain <= 232:
                raise LaunchFileError(f"{where}.domain: {self.domain} is not a DDS domain id (0..232; the robot "
                                      "uses 0, simulation 1)")
        if self.type == "can" and not (self.can_interface and self.channel):
            raise LaunchFileError(f"{where}: a can backend needs can_interface and channel "
                                  "(e.g. socketcan + can0, or virtual + a bus name for tests)")
        if self.type == "serial" and not self.port:
            raise LaunchFileError(f"{where}.port: a serial backend needs the port of the bridge (e.g. /dev/ttyUSB0)")
        if self.mode_pr not in (0, 1):
            raise LaunchFileError(f"{where}.mode_pr: {self.mode_pr} must be 0 (pitch/roll) or 1 (parallel motors)")
        if not 50.0 <= self.command_rate_hz <= 1000.0:
            raise LaunchFileError(f"{where}.command_rate_hz: {self.command_rate_hz} is outside [50, 1000] Hz "
                                  "(the robot expects a steady stream; Unitree's examples use 500)")
        if self.connect_timeout_s <= 0:
            raise LaunchFileError(f"{where}.connect_timeout_s: must be > 0, got {self.connect_timeout_s}")


@dataclass
class DeployConfig:
    """How `g1 deploy` brings a robot up: preflight thresholds and the state machine's timing."""

    ramp_s: float = 3.0
    """Zero torque -> default pose over this long (at least 2 s)."""
    auto_start_s: float = 0.5
    """With --yes: time in zero torque before start is answered."""
    auto_run_s: float = 1.0
    """With --yes: time holding the default pose before run is answered."""
    min_hold_s: float = 0.5
    """The default pose is held at least this long before the policy starts (an earlier run waits)."""
    exit_damping_s: float = 1.0
    """Damping keeps streaming this long before the program exits."""
    min_state_rate_hz: float = 400.0
    state_window_s: float = 1.0
    """Preflight listens to LowState this long to measure its rate and CRC health."""
    max_start_tilt_rad: float = 0.3
    """IMU upright: the pelvis may lean at most this much at start."""
    joint_limit_tolerance_rad: float = 0.02
    """Measured joints may sit this far outside their limits (encoder noise at an end stop)."""
    max_start_temperature_c: float = 70.0
    """Every motor must be cooler than this to start (the runtime trip is safety.max_motor_temperature_c)."""
    min_battery_v: float = 40.0
    """Checked when the transport reports a battery voltage (the G1's LowState_ does not)."""
    dry_run_s: float = 10.0
    """Lockstep MuJoCo run of the same launch file before the robot moves; it must not fall."""
    input_check_s: float = 0.3
    """The operator input is polled this long and must not be lost."""

    def validate(self, where: str) -> None:
        if self.ramp_s < 2.0:
            raise LaunchFileError(f"{where}.ramp_s: {self.ramp_s} s is too fast; ramp to the default pose over "
                                  "at least 2 s")
        if self.dry_run_s < 10.0:
            raise LaunchFileError(f"{where}.dry_run_s: {self.dry_run_s} s; the simulated dry run lasts at least 10 s")
        for name in ("auto_start_s", "auto_run_s", "min_hold_s", "exit_damping_s", "state_window_s", "input_check_s"):
            if getattr(self, name) < 0 or (name in ("state_window_s", "input_check_s") and getattr(self, name) == 0):
                raise LaunchFileError(f"{where}.{name}: must be positive, got {getattr(self, name)}")
        if self.min_state_rate_hz <= 0 or self.max_start_tilt_rad <= 0 or self.joint_limit_tolerance_rad < 0:
            raise LaunchFileError(f"{where}: min_state_rate_hz and max_start_tilt_rad must be positive, "
                                  "joint_limit_tolerance_rad not negative")


@dataclass
class TrackerConfig:
    """Which tracker turns references into motor commands (g1_control/launch/builder.py).

    policy: a velocity-command walking policy (`policy`: a built-in spec name or a spec YAML) with
    upper-body override and closed-loop velocity correction; wbc: the model-based whole-body
    controller (needs rates.tracker_hz >= 200 and a generator with root poses and a contact
    schedule: generator.type scripted); wbt: holosoma's whole-body-tracking policy (50 Hz), kept as
    a comparison baseline for the WBC.
    """

    type: Literal["policy", "wbc", "wbt"] = "policy"
    policy: str = "holosoma_loco_ppo"
    """Built-in spec name (g1 policies list) or a path to a spec YAML."""
    velocity_correction: bool = True


@dataclass
class GeneratorConfig:
    """Which motion generator makes the reference (g1_control/generator/factory.py).

    velocity: the operator's velocity with the style's upper-body pose; backbone: the learned
    in-betweening generator through the IK; interpolation / motion_matching: the same runtime with
    a baseline in-betweener; scripted: a scripted whole-body reference (`reference`, from
    g1_control/generator/scripted.py), for the whole-body controller.
    """

    type: Literal["velocity", "backbone", "learned_motion_matching", "interpolation", "motion_matching",
                  "scripted"] = "velocity"
    model: str = ""
    """Backbone ONNX file (or, for learned_motion_matching, its folder); empty: the shipped model
    (g1_control/policies/generator/). The model must serve the robot's variant
    (backend.expected_variant, backend.hands): it is checked when the launch file is read."""
    feedback: bool = True
    """Reference-guided feedback toward the style's library poses (generator/feedback.py)."""
    reference: str = "stand"
    """type scripted: which reference (stand, arm_wave, crouch, lean_reach, step_in_place, walk)."""
    reference_params: dict[str, float] = field(default_factory=dict)
    """type scripted: the reference's parameters (e.g. {duration_s: 20} for stand, {speed_mps: 0.3}
    for walk; see the functions in g1_control/generator/scripted.py)."""


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
    rates: LoopRates = field(default_factory=LoopRates)
    tracker: TrackerConfig = field(default_factory=TrackerConfig)
    generator: GeneratorConfig = field(default_factory=GeneratorConfig)
    input: InputConfig = field(default_factory=InputConfig)
    limits: LimitsConfig = field(default_factory=LimitsConfig)
    output: OutputConfig = field(default_factory=OutputConfig)
    safety: SafetyConfig = field(default_factory=SafetyConfig)
    """Runtime safety thresholds (g1_control.safety.SafetyConfig); limits.max_tilt_rad still caps the tilt."""
    deploy: DeployConfig = field(default_factory=DeployConfig)
    viewer: bool | Literal["auto"] = "auto"
    """true/false, or auto: open the MuJoCo viewer when a display exists."""
    description: str = ""

    def validate(self, where: str) -> None:
        if self.duration_s is not None and self.duration_s <= 0:
            raise LaunchFileError(f"duration_s: must be > 0, got {self.duration_s}")
        if self.generator.type == "scripted":
            from g1_control.generator.scripted import REFERENCES

            if self.generator.reference not in REFERENCES:
                raise LaunchFileError(f"generator.reference: unknown reference '{self.generator.reference}'; "
                                      f"known: {', '.join(REFERENCES)}")
            import inspect

            accepted = inspect.signature(REFERENCES[self.generator.reference]).parameters
            unknown = sorted(set(self.generator.reference_params) - set(accepted))
            if unknown:
                raise LaunchFileError(f"generator.reference_params: {', '.join(unknown)} not a parameter of reference "
                                      f"'{self.generator.reference}'; known: {', '.join(accepted)}")
        if self.generator.type in ("backbone", "learned_motion_matching", "motion_matching"):
            self._check_generator_variant()
        if self.tracker.type == "wbc":
            if self.rates.tracker_hz < MIN_WBC_TRACKER_HZ:
                raise LaunchFileError(f"rates.tracker_hz: {self.rates.tracker_hz:g} Hz is too slow for tracker.type "
                                      f"wbc (the whole-body controller needs >= {MIN_WBC_TRACKER_HZ:.0f} Hz, e.g. 250)")
            if self.generator.type != "scripted":
                raise LaunchFileError(f"generator.type: tracker.type wbc needs root poses and a contact schedule, "
                                      f"which only generator.type scripted provides (got {self.generator.type})")
        if self.tracker.type == "wbt" and self.rates.tracker_hz != 50.0:
            raise LaunchFileError(f"rates.tracker_hz: tracker.type wbt runs at the policy's 50 Hz, got "
                                  f"{self.rates.tracker_hz:g}")
        lim = self.limits
        for i, seg in enumerate(self.input.timeline):
            for name, limit in (("vx_mps", lim.max_vx_mps), ("vy_mps", lim.max_vy_mps), ("wz_radps", lim.max_wz_radps)):
                value = getattr(seg, name)
                if abs(value) > limit:
                    raise LaunchFileError(f"input.timeline[{i}].{name}: {value} exceeds limits.max_{name} = {limit}")

    def _check_generator_variant(self) -> None:
        """The robot variant must have a generator skeleton, and a given model must serve it."""
        from g1_control.generator.skeleton import SkeletonError, skeleton_for_robot

        try:
            skeleton = skeleton_for_robot(self.backend.expected_variant, self.backend.hands)
            if self.generator.model and self.generator.type != "motion_matching":
                model = Path(self.generator.model)
                folder = model if model.is_dir() else model.parent
                if (folder / "model.json").is_file():
                    import json

                    trained = json.loads((folder / "model.json").read_text()).get("skeletons", ["g1_29dof"])
                    if skeleton not in trained:
                        raise SkeletonError(f"{model} was trained for {', '.join(trained)}; the robot is {skeleton}")
        except SkeletonError as exc:
            raise LaunchFileError(f"generator.model: {exc} (backend.expected_variant "
                                  f"{self.backend.expected_variant}, backend.hands {self.backend.hands})") from None

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
    except SafetyConfigError as exc:
        raise LaunchFileError(f"{source}: safety: {exc}") from None


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
    except Exception as exc:
        raise LaunchFileError(f"{path}: tracker.policy: {exc}") from None
    return launch
