"""The launch-file schema: one YAML per setup, validated completely before anything runs.

    g1 launch launch/sim_walk.yaml --check     # validate only
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

from g1_control.config import apply_overrides, from_dict, read_yaml
from g1_control.errors import LaunchFileError, SafetyConfigError
from g1_control.estimation.external_pose import ExternalPoseConfig
from g1_control.estimation.perception import PerceptionConfig
from g1_control.loop.rates import LoopRates
from g1_control.robot import g1
from g1_control.safety.config import SafetyConfig
from g1_control.safety.fall import FallConfig
from g1_control.scene import FLOOR, SceneConfig
from g1_control.sim.randomize import RandomizeConfig
from g1_control.teleop.scripted import RandomTimelineConfig, Segment
from g1_control.trackers.wbc.contacts import DEFAULT_FRICTION as DEFAULT_FOOT_FRICTION

ROBOT_BACKENDS = ("unitree_dds", "can", "serial")
"""Backends that drive a robot (real, or `g1 sim-robot`) through a robot link; `g1 deploy` runs them."""

VARIANT_NAMES = ("g1_23dof", "g1_29dof", "g1_29dof_locked_waist")

PROGRAM_END_HOLD_S = 1.0
"""A program run goes on this long after its last step (the robot comes to rest; measured)."""

SKELETON_GENERATORS = ("backbone", "learned_motion_matching", "motion_matching")
"""generator.type values that generate for the robot variant's skeleton (backend.expected_variant,
backend.hands): checked when the launch file is read, chosen when the loop is built."""

MIN_WBC_TRACKER_HZ = 100.0
WBC_TRACKER_HZ = 250.0
"""rates.tracker_hz when a launch file with tracker.type wbc or layer does not state it (the policies' 50 Hz
default is too slow for the whole-body controller)."""
"""The whole-body controller's slowest rate in use: every task of issue 17 (standing at any height,
reaching, holding and carrying a box, stepping onto a platform) was tracked at 100 Hz as at
250 Hz in the execution bench's debugging runs (`g1 bench execution --only reach,height,box,step`)."""

MIN_FOOT_FRICTION, MAX_FOOT_FRICTION = 0.05, 1.5
"""tracker.foot_friction's range: ice to the grippiest rubber on a dry floor. Beyond it the friction
pyramid plans forces no floor holds (or a value below ice, where the gait cannot walk at all)."""


@dataclass
class BackendConfig:
    """mujoco: the simulator (g1 launch). unitree_dds / can / serial: a robot link (g1 deploy).

    unitree_dds needs `interface` (the NIC cabled to the robot, or `lo` for `g1 sim-robot`) and
    `domain` (0 on the robot, 1 in simulation); `partition` only isolates concurrent runs on one
    host. can needs `can_interface` + `channel` (python-can: socketcan/can0, virtual/NAME); serial
    needs `port` (+ `baudrate`). `expected_variant` is the G1 the launch file is written for: a
    robot reporting another mode_machine is refused. `simulator` names one of Unitree's own
    simulators behind a unitree_dds link on loopback (g1_control/hardware/unitree/simulators.py:
    unitree_mujoco): the host then accepts what that simulator leaves unset in LowState_ (crc,
    tick, mode_machine at 0, a 200 Hz stream, no motion service), and the preflight says so.
    """

    type: Literal["mujoco", "unitree_dds", "can", "serial"] = "mujoco"
    mode: Literal["lockstep", "wallclock"] = "lockstep"
    physics_dt_s: float = 0.002
    interface: str | None = None
    domain: int = 0
    partition: str | None = None
    release_motion_service: bool = True
    """Release the robot's built-in controller first (false: the operator used the remote's debug mode)."""
    expected_variant: g1.VariantName = "g1_29dof"
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
    simulator: str | None = None
    """None: a robot (or g1 sim-robot), every LowState_ field checked; unitree_mujoco: Unitree's simulator."""
    randomize: RandomizeConfig | None = None
    """mujoco only: a seeded domain randomisation of the simulated robot (link masses, CoM offsets,
    motor strength, command latency, foot friction; g1_control/sim/randomize.py). Absent: the
    nominal robot. The robot path is randomised in `g1 sim-robot --randomize SEED`."""

    def validate(self, where: str) -> None:
        self._validate_simulator(where)
        if not 0.0005 <= self.physics_dt_s <= 0.005:
            raise LaunchFileError(f"{where}.physics_dt_s: {self.physics_dt_s} is outside [0.0005, 0.005] s "
                                  "(physics must run at 200 Hz or faster)")
        if self.hands == "dex3" and self.expected_variant != "g1_29dof":
            raise LaunchFileError(f"{where}.hands: Dex3 hands are modelled on the 29-DoF G1 only; "
                                  f"expected_variant is {self.expected_variant}")
        if self.type == "mujoco":
            return
        if self.randomize is not None:
            raise LaunchFileError(f"{where}.randomize: only the simulator (type mujoco) is randomised here; a "
                                  f"{self.type} backend drives a robot (randomise g1 sim-robot with --randomize SEED)")
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

    def _validate_simulator(self, where: str) -> None:
        from g1_control.hardware.links.network import LOOPBACK
        from g1_control.hardware.unitree.simulators import SIMULATORS

        if self.simulator is None:
            return
        if self.simulator not in SIMULATORS:
            raise LaunchFileError(f"{where}.simulator: '{self.simulator}' is not a simulator profile; known: "
                                  f"{', '.join(SIMULATORS)} (leave it out for a robot)")
        if self.type != "unitree_dds" or self.interface != LOOPBACK:
            raise LaunchFileError(f"{where}.simulator: {self.simulator} is allowed on loopback only (type unitree_dds, "
                                  f"interface {LOOPBACK}); got type {self.type}, interface {self.interface}: a robot "
                                  "must fill crc, tick and mode_machine, and is checked for them")


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
    """Every motor must be cooler than this to start (the runtime trip is safety.max_motor_temperature_c); at
    most the motors' rating (robot.g1.MOTOR_MAX_TEMPERATURE_C)."""
    min_battery_v: float = 40.0
    """Checked when the transport reports a battery voltage (the G1's LowState_ does not); inside the pack's
    range (robot.g1.BATTERY_EMPTY_V, BATTERY_FULL_V), where the check can fire."""
    dry_run_s: float = 10.0
    """Lockstep MuJoCo run of the same launch file before the robot moves; it must not fall."""
    input_check_s: float = 0.3
    """The operator input is polled this long and must not be lost."""
    realtime_priority: int = 20
    """SCHED_RR priority of the deploy process (1..99; 0: normal scheduling): ordinary work on the host
    cannot delay a real-time loop (g1_control/loop/priority.py). Needs root or CAP_SYS_NICE; without,
    it falls back to nice -10 with a warning. The simulated dry run runs at normal priority."""

    def validate(self, where: str) -> None:
        if self.ramp_s < 2.0:
            raise LaunchFileError(f"{where}.ramp_s: {self.ramp_s} s is too fast; ramp to the default pose over "
                                  "at least 2 s")
        if self.dry_run_s < 10.0:
            raise LaunchFileError(f"{where}.dry_run_s: {self.dry_run_s} s; the simulated dry run lasts at least 10 s")
        for name in ("auto_start_s", "auto_run_s", "min_hold_s", "exit_damping_s", "state_window_s", "input_check_s"):
            if getattr(self, name) < 0 or (name in ("state_window_s", "input_check_s") and getattr(self, name) == 0):
                raise LaunchFileError(f"{where}.{name}: must be positive, got {getattr(self, name)}")
        if not 0 <= self.realtime_priority <= 99:
            raise LaunchFileError(f"{where}.realtime_priority: {self.realtime_priority} is not a real-time priority "
                                  "(1..99, or 0 for normal scheduling)")
        if self.max_start_temperature_c > g1.MOTOR_MAX_TEMPERATURE_C:
            raise LaunchFileError(f"{where}.max_start_temperature_c: {self.max_start_temperature_c} °C is above the "
                                  f"motors' rating ({g1.MOTOR_MAX_TEMPERATURE_C:g} °C); the start check could never "
                                  "refuse a motor in time")
        if not g1.BATTERY_EMPTY_V < self.min_battery_v < g1.BATTERY_FULL_V:
            never = "fire (the pack is never that low)" if self.min_battery_v <= g1.BATTERY_EMPTY_V else \
                "pass (the pack is never that high)"
            raise LaunchFileError(f"{where}.min_battery_v: {self.min_battery_v} V is outside the G1 battery's range "
                                  f"({g1.BATTERY_EMPTY_V:g} V empty, {g1.BATTERY_FULL_V:g} V full); the check could "
                                  f"never {never}")
        if self.min_state_rate_hz <= 0 or self.max_start_tilt_rad <= 0 or self.joint_limit_tolerance_rad < 0:
            raise LaunchFileError(f"{where}: min_state_rate_hz and max_start_tilt_rad must be positive, "
                                  "joint_limit_tolerance_rad not negative")


@dataclass
class TrackerConfig:
    """Which tracker turns references into motor commands (g1_control/launch/builder.py).

    policy: a velocity-command walking policy (`policy`: a built-in spec name or a spec YAML) with
    upper-body override and closed-loop velocity correction; wbc: the model-based whole-body
    controller (needs rates.tracker_hz >= 100; 250 when the file states none): with generator.type scripted its feet follow the
    reference's contact schedule, with any other generator it walks by its own gait from the
    reference's root twist (g1_control/trackers/wbc/gait.py), at the pelvis height a command asks, and
    in a scene it executes goals too (LaunchFile.executes_goals: it follows their whole-body plans and
    walks with a held box by its gait); wbt: holosoma's whole-body-tracking policy (50 Hz), kept as
    a comparison baseline for the WBC; layer: the tracking layer that executes goals - the walking
    policy while the plan walks, the WBC for whole-body phases (manipulation, stepping onto
    platforms, standing heights the policy cannot hold), with a blended hand-over
    (g1_control/trackers/layer.py); rates.tracker_hz is the WBC's (>= 100 Hz, 250 unstated), the policy runs at
    its own 50 Hz inside it.
    """

    type: Literal["policy", "wbc", "wbt", "layer"] = "policy"
    policy: str = "holosoma_loco_ppo"
    """Built-in spec name (g1 policies list) or a path to a spec YAML."""
    velocity_correction: bool = True
    envelope_limits: bool = True
    """Operator command limits from the policy's measured envelope (`g1 bench envelope`, shipped next
    to its spec); false: from the range it was trained on (what the envelope bench measures)."""
    foot_friction: float = DEFAULT_FOOT_FRICTION
    """wbc and layer: the foot-floor friction coefficient the whole-body controller plans its contact
    forces within (g1_control/trackers/wbc/contacts.py; the default is conservative for a floor
    nobody measured). Not the simulator's friction: a floor known to grip better may raise it."""

    def validate(self, where: str) -> None:
        if not MIN_FOOT_FRICTION <= self.foot_friction <= MAX_FOOT_FRICTION:
            raise LaunchFileError(f"{where}.foot_friction: {self.foot_friction:g} is outside [{MIN_FOOT_FRICTION:g}, "
                                  f"{MAX_FOOT_FRICTION:g}] (the foot-floor friction coefficient the whole-body "
                                  "controller assumes)")


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
    foot_lock: bool = True
    """Hold each plan's stance feet where they stand (generator/foot_lock.py); false: the
    in-betweener's feet as it made them (they slide about 0.2 m/s at a 30-frame gap)."""
    reference: str = "stand"
    """type scripted: which reference (stand, arm_wave, crouch, lean_reach, step_in_place, walk)."""
    reference_params: dict[str, float] = field(default_factory=dict)
    """type scripted: the reference's parameters (e.g. {duration_s: 20} for stand, {speed_mps: 0.3}
    for walk; see the functions in g1_control/generator/scripted.py)."""


@dataclass
class IKSection:
    """The IK stage between generator and tracker (g1_control/ik/stage.py: IKStage). A reference
    the generator made feasible by construction (velocity, scripted, a goal's whole-body plan)
    passes through; any other (backbone and the other learned generators) is solved by the
    differential-IK QP (g1_control/ik/retargeter.py: IKRetargeter) with these settings, one solve
    per tracker tick (its time step is 1 / rates.tracker_hz). The names are IKConfig's.

    The defaults are the loop's: the legs belong to the walking policy. Holding stance feet where
    they touched down or moving the CoM would make the IK bend the arms to reach a generated root
    the real robot is not at (measured: it swung both arms overhead and tipped the robot over), so
    contacts are free and the CoM has no cost; what the IK adds is feasibility of the upper body
    (joint position and velocity limits, smoothness) and effector goals as frame targets.
    """

    backend: Literal["daqp", "proxqp"] = "daqp"
    """The QP solver (g1_control/ik/solver.py)."""
    iterations: int = 1
    """QP steps per tick (one is enough online: the target moves little per tick)."""
    root_cost: tuple[float, float] = (10.0, 5.0)
    """(position 1/m, orientation 1/rad) cost of the pelvis following the reference root pose."""
    com_cost: tuple[float, float, float] = (0.0, 0.0, 0.0)
    """Per world axis: the CoM follows the reference posture's CoM (0: free, see above)."""
    posture_cost: float = 0.3
    default_frame_cost: tuple[float, float] = (5.0, 1.0)
    """(position, orientation) cost of a frame target (an effector goal) not in frame_costs."""
    frame_costs: dict[str, tuple[float, float]] = field(default_factory=dict)
    """Per frame name (a link of the G1 model): (position, orientation) cost."""
    damping_cost: float = 1e-3
    smoothness_cost: float = 0.05
    velocity_limit_scale: float = 1.0
    """Fraction of the motors' velocity limits the IK may use, in (0, 1]."""
    joint_margin_rad: float = 0.0
    """The IK keeps the joints this far inside their position limits."""
    hold_contacts: bool = False
    """Hold stance feet where they touched down (off in the loop, see above)."""
    enforce_ground: bool = True
    """Keep the feet above the floor."""
    self_collision: bool = False
    """Keep every pair of non-adjacent links apart (the URDF's collision meshes; costs CPU)."""

    def validate(self, where: str) -> None:
        if self.iterations < 1:
            raise LaunchFileError(f"{where}.iterations: {self.iterations} must be >= 1 (QP steps per tick)")
        costs = {"root_cost": self.root_cost, "com_cost": self.com_cost, "posture_cost": (self.posture_cost,),
                 "default_frame_cost": self.default_frame_cost, "damping_cost": (self.damping_cost,),
                 "smoothness_cost": (self.smoothness_cost,)}
        costs.update({f"frame_costs.{name}": cost for name, cost in self.frame_costs.items()})
        for name, values in costs.items():
            if any(v < 0 for v in values):
                shown = values[0] if len(values) == 1 else list(values)
                raise LaunchFileError(f"{where}.{name}: {shown} has a negative cost (costs are >= 0; 0 disables)")
        if not 0.0 < self.velocity_limit_scale <= 1.0:
            raise LaunchFileError(f"{where}.velocity_limit_scale: {self.velocity_limit_scale} is outside (0, 1] "
                                  "(a fraction of the motors' velocity limits)")
        if not 0.0 <= self.joint_margin_rad < 0.2:
            raise LaunchFileError(f"{where}.joint_margin_rad: {self.joint_margin_rad} is outside [0, 0.2) rad")


TELEOP_DEVICES = ("gamepad", "keyboard", "unitree_remote")


@dataclass
class InputConfig:
    """Where commands come from.

    scripted: `timeline` segments; random: seeded random segments; gamepad / keyboard /
    unitree_remote: a teleop device configured by `device` (path, mapping; see
    g1_control/teleop/README.md); gamepad_script: a timed gamepad sequence (`gamepad_script`)
    played through the real evdev gamepad reader, for recorded demos and tests.
    """

    type: Literal["scripted", "random", "gamepad", "keyboard", "unitree_remote", "gamepad_script",
                  "program", "ros2"] = "scripted"
    timeline: list[Segment] = field(default_factory=list)
    random: RandomTimelineConfig = field(default_factory=RandomTimelineConfig)
    device: dict[str, Any] = field(default_factory=dict)
    fallback: Literal["keyboard"] | None = None
    """For a gamepad with path 'auto': use the keyboard when no gamepad is plugged in."""
    gamepad_script: list[dict[str, Any]] = field(default_factory=list)
    program: list[dict[str, Any]] = field(default_factory=list)
    """type program: the behaviour program's steps (g1_control/program/README.md), e.g.
    [{kind: walk, distance_m: 2.0}, {kind: turn, angle_rad: 1.5708}]."""
    instruction: str = ""
    """type program: an English instruction instead of `program` (parsed when the file is loaded)."""
    places: dict[str, dict[str, Any]] = field(default_factory=dict)
    """type program: named places besides the scene's ({door: {pos_w_m: [3, 0, 0], kind: point}})."""
    pose: Literal["estimator", "ground_truth"] = "estimator"
    """type program: what the runner steers by: the robot's own estimate (IMU yaw, leg odometry), or,
    in simulation only, the simulator's pose. Steps are judged from ground truth either way."""
    start_delay_s: float = 1.0
    """type program: standing time before the first step."""

    def validate(self, where: str) -> None:
        if self.type == "scripted" and not self.timeline:
            raise LaunchFileError(f"{where}.timeline: a scripted input needs at least one segment")
        if self.type == "program":
            self.parsed_program(where)
        elif self.program or self.instruction:
            raise LaunchFileError(f"{where}.{'program' if self.program else 'instruction'}: only input.type program "
                                  f"runs a program (got type {self.type})")
        if self.start_delay_s < 0:
            raise LaunchFileError(f"{where}.start_delay_s: must be >= 0, got {self.start_delay_s}")
        if self.type == "ros2":
            from g1_control.teleop.ros2 import ros2_settings

            ros2_settings(self.device, f"{where}.device")
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

    def parsed_program(self, where: str = "input"):
        """The program (g1_control.program.Program) `program` or `instruction` describes; errors name the key."""
        from g1_control.program import InstructionError, Program, ProgramError, parse_instruction
        from g1_control.program.steps import Step

        if bool(self.program) == bool(self.instruction):
            raise LaunchFileError(f"{where}: input.type program needs `program` (a list of steps) or `instruction` "
                                  "(English), one of them")
        if self.instruction:
            try:
                return parse_instruction(self.instruction)
            except InstructionError as exc:
                raise LaunchFileError(f"{where}.instruction: {exc}") from None
        try:
            steps = [Step.from_dict(s, f"{where}.program[{i}]") for i, s in enumerate(self.program)]
            return Program(steps).validate()
        except ProgramError as exc:
            raise LaunchFileError(str(exc)) from None

    def world(self, where: str = "input"):
        """The named places of `places` (g1_control.program.World)."""
        from g1_control.program import ProgramError, World

        try:
            return World.from_dict(self.places)
        except ProgramError as exc:
            raise LaunchFileError(f"{where}.{str(exc).removeprefix('world.')}") from None


STEER_BY = ("auto", "ground_truth", "estimate")


@dataclass
class EstimationConfig:
    """Where the robot is (g1_control/estimation/localiser.py): what goals and programs steer by.

    steer_by auto: the simulator's ground truth where the backend gives it (MuJoCo: g1 launch), the
    robot's own estimate (leg odometry, fused with external_pose where given) on a robot link;
    estimate: the estimate everywhere (to try in simulation what the robot will do); ground_truth:
    MuJoCo only. The estimate is anchored where the run starts: the launch file's scene is relative
    to the robot's start (the origin, facing +x). Outcomes are judged from ground truth either way.
    external_pose: a geometry_msgs/PoseStamped topic (motion capture, SLAM; g1 sim-robot --mocap)
    fused with the leg odometry (g1_control/estimation/external_pose.py).
    """

    steer_by: Literal["auto", "ground_truth", "estimate"] = "auto"
    external_pose: ExternalPoseConfig | None = None
    perception: PerceptionConfig | None = None
    """Object poses arriving at run time (g1_control/estimation/perception.py; g1 sim-robot --scene):
    the scene's boxes move to where perception sees them, placed with the estimate, and the platforms
    it sees (on the topic + /platforms) take the place of the scene's or join it; a step goal may then
    name a platform the scene does not list."""


@dataclass
class LimitsConfig:
    max_vx_mps: float = 1.0
    max_vy_mps: float = 0.6
    max_wz_radps: float = 1.0
    max_tilt_rad: float = 1.0
    """Beyond this pelvis tilt the robot counts as fallen and the loop damps it (below pi: no tilt exceeds pi)."""

    def validate(self, where: str) -> None:
        for name in ("max_vx_mps", "max_vy_mps", "max_wz_radps", "max_tilt_rad"):
            value = getattr(self, name)
            if not value > 0:
                raise LaunchFileError(f"{where}.{name}: {value} must be > 0 (a limit on the magnitude, both "
                                      "directions)")
        if self.max_tilt_rad >= math.pi:
            raise LaunchFileError(f"{where}.max_tilt_rad: {self.max_tilt_rad} rad must be below pi ({math.pi:.4f}): "
                                  "no tilt exceeds pi, so the fall could never be detected")


@dataclass
class OutputConfig:
    dir: str = "runs"
    video: bool | Literal["auto"] = "auto"
    """true/false, or auto: render when headless rendering (EGL or OSMesa) works."""
    video_fps: float = 10.0
    video_size: tuple[int, int] = (480, 360)
    plot: bool = True


@dataclass
class PushConfig:
    """A shove on the pelvis in simulation (g1 launch only): does the robot recover?"""

    at_s: float
    force_h_n: tuple[float, float, float]
    """Heading frame at the push's start: x forward, y left, z up (a push "from the right" is +y)."""
    duration_s: float = 0.2
    label: str = ""

    def validate(self, where: str) -> None:
        if self.at_s < 0 or not 0 < self.duration_s <= 2.0:
            raise LaunchFileError(f"{where}: at_s must be >= 0 and duration_s in (0, 2] s; got at_s {self.at_s}, "
                                  f"duration_s {self.duration_s}")
        if len(self.force_h_n) != 3:
            raise LaunchFileError(f"{where}.force_h_n: need 3 numbers (x forward, y left, z up), got {self.force_h_n}")


@dataclass
class LaunchFile:
    name: str
    duration_s: float | None = None
    """Run length; defaults to the timeline's total."""
    backend: BackendConfig = field(default_factory=BackendConfig)
    rates: LoopRates = field(default_factory=LoopRates)
    tracker: TrackerConfig = field(default_factory=TrackerConfig)
    generator: GeneratorConfig = field(default_factory=GeneratorConfig)
    ik: IKSection = field(default_factory=IKSection)
    """The IK stage (absent: the loop's defaults, IKSection)."""
    input: InputConfig = field(default_factory=InputConfig)
    limits: LimitsConfig = field(default_factory=LimitsConfig)
    output: OutputConfig = field(default_factory=OutputConfig)
    safety: SafetyConfig = field(default_factory=SafetyConfig)
    """Runtime safety thresholds (g1_control.safety.SafetyConfig); limits.max_tilt_rad still caps the tilt."""
    fall: FallConfig = field(default_factory=FallConfig)
    """What counts as a fall besides the tilt (g1_control/safety/fall.py): pelvis height, allowed ground contacts."""
    deploy: DeployConfig = field(default_factory=DeployConfig)
    viewer: bool | Literal["auto"] = "auto"
    """true/false, or auto: open the MuJoCo viewer when a display exists."""
    description: str = ""
    scene: SceneConfig = field(default_factory=SceneConfig)
    """Tables, platforms and boxes around the robot (g1_control/scene.py); goals refer to them by name."""
    estimation: EstimationConfig = field(default_factory=EstimationConfig)
    """What goals and programs steer by (the estimate on a robot) and an optional external pose input."""

    pushes: list[PushConfig] = field(default_factory=list)
    """Shoves on the pelvis during a simulated run; the summary says whether each was recovered."""

    def steers_by_estimate(self) -> bool:
        """Whether goals and programs steer by the robot's own estimate (estimation.steer_by)."""
        steer = self.estimation.steer_by
        return steer == "estimate" or (steer == "auto" and self.backend.type != "mujoco")

    def _validate_estimation(self) -> None:
        est = self.estimation
        if est.steer_by == "ground_truth" and self.backend.type != "mujoco":
            raise LaunchFileError(f"estimation.steer_by: ground_truth needs a simulator's ground truth; backend.type "
                                  f"{self.backend.type} drives a robot, which reports none (use auto or estimate)")
        if est.perception is not None and not self.steers_by_estimate():
            raise LaunchFileError("estimation.perception: objects are placed with the robot's estimate, which this "
                                  f"MuJoCo run does not steer by (steer_by {est.steer_by}: ground truth); set "
                                  "estimation.steer_by: estimate to use it")
        if est.external_pose is not None and not self.steers_by_estimate():
            raise LaunchFileError("estimation.external_pose: the external pose is fused into the robot's estimate, "
                                  "which this MuJoCo run does not steer by (steer_by "
                                  f"{est.steer_by}: ground truth); set estimation.steer_by: estimate to use it")

    def validate(self, where: str) -> None:
        self._validate_estimation()
        if self.duration_s is not None and self.duration_s <= 0:
            raise LaunchFileError(f"duration_s: must be > 0, got {self.duration_s}")
        if self.pushes and self.backend.type != "mujoco":
            raise LaunchFileError("pushes: only a simulated run (backend.type mujoco) can be pushed")
        if self.generator.type == "scripted":
            from g1_control.generator.scripted import REFERENCES

            if self.generator.reference not in REFERENCES:
                raise LaunchFileError(f"generator.reference: unknown reference '{self.generator.reference}'; "
                                      f"known: {', '.join(REFERENCES)}")
            import inspect

            # the robot variant is backend.expected_variant's, never a reference parameter
            accepted = [p for p in inspect.signature(REFERENCES[self.generator.reference]).parameters if p != "variant"]
            unknown = sorted(set(self.generator.reference_params) - set(accepted))
            if unknown:
                raise LaunchFileError(f"generator.reference_params: {', '.join(unknown)} not a parameter of reference "
                                      f"'{self.generator.reference}'; known: {', '.join(accepted)}")
        if self.generator.type in SKELETON_GENERATORS:
            self._check_generator_variant()
        if self.tracker.type in ("wbc", "layer"):
            if self.rates.tracker_hz < MIN_WBC_TRACKER_HZ:
                raise LaunchFileError(f"rates.tracker_hz: {self.rates.tracker_hz:g} Hz is too slow for tracker.type "
                                      f"{self.tracker.type} (the whole-body controller needs >= "
                                      f"{MIN_WBC_TRACKER_HZ:.0f} Hz, e.g. 100)")
        if self.tracker.type == "layer":
            if self.generator.type == "scripted":
                raise LaunchFileError("generator.type: tracker.type layer plans its own whole-body phases; use "
                                      "velocity (or backbone) for the walking in between, not scripted")
            if self.rates.tracker_hz % 50.0:
                raise LaunchFileError(f"rates.tracker_hz: {self.rates.tracker_hz:g} Hz; tracker.type layer runs "
                                      "the 50 Hz walking policy every n-th tick, so use a multiple of 50 (e.g. 100)")
        if self.tracker.type == "wbt" and self.rates.tracker_hz != 50.0:
            raise LaunchFileError(f"rates.tracker_hz: tracker.type wbt runs at the policy's 50 Hz, got "
                                  f"{self.rates.tracker_hz:g}")
        self._validate_goals()
        if self.input.type == "program":
            from g1_control.program import ProgramError

            try:
                self.input.parsed_program().validate(self.program_world())
            except ProgramError as exc:
                raise LaunchFileError(f"input.program: {exc}") from None
        from g1_control.generator.styles import STYLES

        styles = [(f"input.timeline[{i}].style", seg.style) for i, seg in enumerate(self.input.timeline)]
        styles.append(("input.random.style", self.input.random.style))
        for key, style in styles:
            if style not in STYLES:
                raise LaunchFileError(f"{key}: unknown style '{style}'; known: {', '.join(STYLES)}")
        lim = self.limits
        for i, seg in enumerate(self.input.timeline):
            for name, limit in (("vx_mps", lim.max_vx_mps), ("vy_mps", lim.max_vy_mps), ("wz_radps", lim.max_wz_radps)):
                value = getattr(seg, name)
                if abs(value) > limit:
                    raise LaunchFileError(f"input.timeline[{i}].{name}: {value} exceeds limits.max_{name} = {limit}")

    def _validate_goals(self) -> None:
        """Timeline goals: a tracker that executes them, and names the scene has, of the right kind."""
        sc = self.scene
        for i, seg in enumerate(self.input.timeline):
            for j, goal in enumerate(seg.goals):
                where = f"input.timeline[{i}].goals[{j}]"
                if not self.executes_goals:
                    raise LaunchFileError(f"{where}: goals are executed by tracker.type layer (got "
                                          f"{self.tracker.type}; or wbc with a scene and a generator other than scripted)")
                if goal.object is not None and sc.box(goal.object) is None and sc.bottle(goal.object) is None:
                    objects = [b.name for b in sc.boxes] + [b.name for b in sc.bottles]
                    raise LaunchFileError(f"{where}.object: '{goal.object}' is not a box or bottle of the scene; known: "
                                          f"{', '.join(objects) or 'none (scene.boxes and scene.bottles are empty)'}")
                if goal.object is not None and sc.bottle(goal.object) is not None:
                    if self.backend.hands != "dex3":
                        raise LaunchFileError(f"{where}: picking bottle '{goal.object}' takes a Dex3 hand "
                                              f"(backend.hands: dex3; got {self.backend.hands})")
                    if self.backend.type != "mujoco":
                        raise LaunchFileError(f"{where}: picking bottle '{goal.object}' needs the simulator for now "
                                              f"(backend.type mujoco; got {self.backend.type}): on the robot the loop "
                                              "does not drive the Dex3 fingers yet (`g1 hands grasp` does, alone)")
                    if goal.hand == "both":
                        raise LaunchFileError(f"{where}.hand: a bottle is picked with one hand (left or right)")
                # a platform perception may see at run time need not be in the scene (a goal whose platform
                # is never seen refuses then, before anything moves: generator/goals/platform.py)
                perceived = self.estimation.perception is not None and goal.kind in ("step_up", "step_down")
                if goal.target is not None:
                    known = [p.name for p in sc.platforms] if goal.kind in ("step_up", "step_down") else \
                        sc.block_names() + [FLOOR]
                    if goal.kind == "reach":
                        known = sc.names()
                    if goal.target not in known and not (perceived and goal.target not in sc.names()):
                        what = "a platform" if goal.kind in ("step_up", "step_down") else "a place"
                        raise LaunchFileError(f"{where}.target: '{goal.target}' is not {what} of the scene; known: "
                                              f"{', '.join(known) or 'none'}")
                if goal.kind in ("pick", "place") and not (sc.boxes or sc.bottles):
                    raise LaunchFileError(f"{where}: a {goal.kind} goal needs a box in scene.boxes (or a bottle in "
                                          "scene.bottles)")
                if goal.kind == "step_up" and not sc.platforms and not perceived:
                    raise LaunchFileError(f"{where}: a step_up goal needs a platform in scene.platforms")

    def program_world(self):
        """Places a behaviour program may name (g1_control.program.World): the scene's tables,
        platforms and boxes, and input.places."""
        from g1_control.program import ProgramError, World

        extra = self.input.world()
        try:
            return World.from_scene(self.scene, extra)
        except ProgramError as exc:
            raise LaunchFileError(f"input.{str(exc).removeprefix('world.')}") from None
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
    def executes_goals(self) -> bool:
        """Whether task goals run (the generator inside a GoalGenerator, g1_control/generator/goals/):
        tracker.type layer, or wbc walking by its own gait (a generator other than scripted) in a
        scene with boxes (or bottles), where it walks with a held box too. A scene of platforms only leaves the wbc
        its own gait (it steps onto them from the scene's terrain; step goals on wbc are not wired)."""
        return self.tracker.type == "layer" or (self.tracker.type == "wbc" and self.generator.type != "scripted"
                                                and bool(self.scene.boxes or self.scene.bottles))

    @property
    def total_duration_s(self) -> float:
        if self.duration_s is not None:
            return self.duration_s
        if self.input.type == "scripted":
            return sum(s.duration_s for s in self.input.timeline)
        if self.input.type == "gamepad_script" and self.input.gamepad_script:
            return float(self.input.gamepad_script[-1]["t_s"]) + 3.0
        if self.input.type == "program":  # an upper bound: the run ends when the program does
            from g1_control.program.runner import time_budget_s

            return self.input.start_delay_s + time_budget_s(self.input.parsed_program()) + PROGRAM_END_HOLD_S
        return 60.0


def _wbc_rate_default(data):
    """`data` with rates.tracker_hz at WBC_TRACKER_HZ when the tracker is the whole-body controller and the
    file does not state a rate (`g1 launch sim_generator --set tracker.type=wbc` runs at the WBC's rate)."""
    if not isinstance(data, dict) or not isinstance(data.get("tracker"), dict):
        return data
    rates = data.get("rates", {})
    if data["tracker"].get("type") not in ("wbc", "layer") or not isinstance(rates, dict) or "tracker_hz" in rates:
        return data
    return {**data, "rates": {**rates, "tracker_hz": WBC_TRACKER_HZ}}


def parse_launch(data, source: str = "<launch>") -> LaunchFile:
    from g1_control.launch.start_pose import to_start_frame

    try:
        return from_dict(LaunchFile, to_start_frame(_wbc_rate_default(data)), "")
    except LaunchFileError as exc:
        raise LaunchFileError(f"{source}: {exc}") from None
    except SafetyConfigError as exc:  # SafetyConfig's own messages, or fall.* (FallConfig, which names its key)
        raise LaunchFileError(f"{source}: {'safety: ' if str(exc).startswith('SafetyConfig') else ''}{exc}") from None


def load_launch(path: str | Path, overrides: Iterable[str] = ()) -> LaunchFile:
    """Read and validate a launch file; raise LaunchFileError naming the file and key on any problem.

    `overrides`: dotted `KEY=VALUE` settings (`g1 launch FILE --set tracker.policy=...`), applied
    before validation, so they pass the same schema (g1_control/config.py:apply_overrides).
    """
    path = Path(path)
    if not path.is_file():
        raise LaunchFileError(f"{path}: no such launch file")
    data = read_yaml(path)
    if overrides:
        try:
            data = apply_overrides(data, overrides)
        except LaunchFileError as exc:
            raise LaunchFileError(f"{path}: {exc}") from None
    launch = parse_launch(data, str(path))
    # The tracker's policy must resolve and fit the robot before anything runs.
    from g1_control.trackers.policy_spec import resolve_spec_path

    try:
        resolve_spec_path(launch.tracker.policy)
    except Exception as exc:
        raise LaunchFileError(f"{path}: tracker.policy: {exc}") from None
    return launch
