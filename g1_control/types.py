"""Plain data passed between the stages of one control tick.

Arrays are float64 numpy arrays in the robot's joint order (g1_control.robot.g1.JOINT_NAMES);
units are in the field names. Quaternions are (w, x, y, z). "_w" is the world frame, "_b" the
base (pelvis) frame, "_h" the heading frame (the world turned by the base's yaw: x forward along
the ground, y left, z up). Nothing here does I/O or math beyond validation.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from enum import Enum
from types import MappingProxyType
from typing import Any

import numpy as np

from g1_control.errors import InvalidCommandError, InvalidStateError, LaunchFileError
from g1_control.robot import dex3
from g1_control.robot.g1 import DEFAULT_PELVIS_HEIGHT_M, NUM_JOINTS

_sum = np.add.reduce
"""ndarray.sum without its Python wrapper (the per-tick finite checks sum small arrays)."""


def _zeros() -> np.ndarray:
    return np.zeros(NUM_JOINTS)


class Button(str, Enum):
    """Operator buttons a Command may carry (edges: present on the tick they were pressed). A str
    enum: `"stop" in command.buttons` and `Button.STOP in command.buttons` are the same test."""

    START = "start"
    """Ramp to the default pose (g1 deploy)."""
    STOP = "stop"
    """Stop: damping, for good (g1 deploy)."""
    ESTOP = "estop"
    """Emergency stop: damping at once, from any state."""
    RUN = "run"
    """Hand the robot to the tracker (g1 deploy)."""
    STYLE_NEXT = "style_next"
    STYLE_PREV = "style_prev"
    POLICY_SWITCH = "policy_switch"
    DAMP = "damp"
    """Damping now (the remote's select)."""


BUTTONS = frozenset(b.value for b in Button)
"""Every button name a Command may carry."""


# -- command limits -------------------------------------------------------------------------------------
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

    def intersect(self, other: CommandLimits) -> CommandLimits:
        """The ranges both allow."""
        def both(a: tuple[float, float], b: tuple[float, float]) -> tuple[float, float]:
            return max(a[0], b[0]), min(a[1], b[1])

        return CommandLimits(both(self.vx_mps, other.vx_mps), both(self.vy_mps, other.vy_mps),
                             both(self.wz_radps, other.wz_radps), both(self.pelvis_height_m, other.pelvis_height_m))

    @classmethod
    def symmetric(cls, vx_mps: float, vy_mps: float, wz_radps: float) -> CommandLimits:
        return cls((-vx_mps, vx_mps), (-vy_mps, vy_mps), (-wz_radps, wz_radps))

    def clamp_velocity(self, vx: float, vy: float, wz: float) -> tuple[float, float, float]:
        return (min(max(vx, self.vx_mps[0]), self.vx_mps[1]), min(max(vy, self.vy_mps[0]), self.vy_mps[1]),
                min(max(wz, self.wz_radps[0]), self.wz_radps[1]))


@dataclass
class EffectorGoal:
    """Put a named robot frame at a world point (optionally by time t_s from now)."""

    frame: str
    pos_w_m: np.ndarray
    t_s: float | None = None


GOAL_KINDS = ("reach", "pick", "place", "step_up", "step_down")
"""What the execution layer (g1_control/generator/goals/) can be asked to do."""
HANDS = ("left", "right", "both")


@dataclass
class TaskGoal:
    """A goal for the execution layer, against the scene (g1_control/scene.py):

    reach      put `hand` (left/right/both) at pos_w_m (world point), or at its standing position
               moved by offset_h_m (heading frame: x forward, y left, z up); then hold it there
    pick       pick box `object` (None: the nearest box in front) with both hands and hold it
    place      set the held box down: on table/platform `target` (at pos_w_m's xy if given, else
               the middle of its near edge), or at pos_w_m (floor), or (neither) in front
    step_up    step onto platform `target` (None: the nearest in front) and stand on it
    step_down  step off the platform the robot stands on (back where it came from, then back clear of
               its edge: GoalConfig.clear_of_platform_m) and stand

    A goal is started the first tick a Command carries its `goal_id` and runs to its end even
    when later commands no longer carry it; goals queue in the order they arrive.
    """

    kind: str
    goal_id: str = ""
    hand: str = "right"
    object: str | None = None
    target: str | None = None
    pos_w_m: np.ndarray | None = None
    offset_h_m: np.ndarray | None = None

    def validate(self) -> TaskGoal:
        if self.kind not in GOAL_KINDS:
            raise InvalidCommandError(f"TaskGoal.kind '{self.kind}' is not one of {', '.join(GOAL_KINDS)}")
        if self.hand not in HANDS:
            raise InvalidCommandError(f"TaskGoal.hand '{self.hand}' is not one of {', '.join(HANDS)}")
        if self.pos_w_m is not None:
            pos = np.asarray(self.pos_w_m, dtype=float)
            if pos.shape != (3,) or not np.all(np.isfinite(pos)):
                raise InvalidCommandError(f"TaskGoal '{self.goal_id}' ({self.kind}) has position {self.pos_w_m!r}; "
                                          "it must be 3 finite numbers")
        if self.offset_h_m is not None:
            off = np.asarray(self.offset_h_m, dtype=float)
            if off.shape != (3,) or not np.all(np.isfinite(off)):
                raise InvalidCommandError(f"TaskGoal '{self.goal_id}' has offset {self.offset_h_m!r}; "
                                          "it must be 3 finite numbers")
        if self.kind == "reach" and (self.pos_w_m is None) == (self.offset_h_m is None):
            raise InvalidCommandError(f"TaskGoal '{self.goal_id}': a reach needs pos_w_m or offset_h_m (one of them)")
        return self

    def describe(self) -> str:
        what = {"reach": f"reach {self.hand} hand", "pick": f"pick {self.object or 'the box in front'}",
                "place": "place" + (f" {self.object}" if self.object else ""), "step_up": "step up",
                "step_down": "step down"}[self.kind]
        if self.target:
            what += f" {'on' if self.kind != 'reach' else 'to'} {self.target}"
        if self.pos_w_m is not None:
            what += " at (" + ", ".join(f"{v:.2f}" for v in self.pos_w_m) + ")"
        return what


@dataclass
class Command:
    """Operator intent for one tick."""

    vx_mps: float = 0.0
    vy_mps: float = 0.0
    wz_radps: float = 0.0
    heading_rad: float | None = None
    style: str = "default"
    pelvis_height_m: float | None = None
    goals: list[EffectorGoal] = field(default_factory=list)
    tasks: list[TaskGoal] = field(default_factory=list)
    """Goals for the execution layer (reach, pick, place, step up/down; see TaskGoal)."""
    buttons: frozenset[str] = frozenset()

    def validate(self) -> Command:
        """Raise InvalidCommandError naming the first bad field; return self when fine."""
        for name in ("vx_mps", "vy_mps", "wz_radps", "heading_rad", "pelvis_height_m"):
            value = getattr(self, name)
            if value is not None and not math.isfinite(value):
                raise InvalidCommandError(f"Command.{name} is {value}; it must be a finite number")
        for goal in self.goals:
            pos = np.asarray(goal.pos_w_m, dtype=float)
            if pos.shape != (3,) or not np.all(np.isfinite(pos)):
                raise InvalidCommandError(
                    f"Command goal for frame '{goal.frame}' has position {goal.pos_w_m!r}; "
                    "it must be 3 finite numbers"
                )
        for task in self.tasks:
            task.validate()
        if not BUTTONS.issuperset(self.buttons):
            unknown = set(self.buttons) - BUTTONS
            raise InvalidCommandError(
                f"Command has unknown buttons {sorted(unknown)}; known: {sorted(BUTTONS)}"
            )
        return self


@dataclass
class RobotState:
    """What the robot (or simulator) reports, as the low-level protocol carries it."""

    t_s: float = 0.0
    q_rad: np.ndarray = field(default_factory=_zeros)
    dq_radps: np.ndarray = field(default_factory=_zeros)
    tau_nm: np.ndarray = field(default_factory=_zeros)
    imu_quat_wxyz: np.ndarray = field(default_factory=lambda: np.array([1.0, 0.0, 0.0, 0.0]))
    imu_gyro_radps: np.ndarray = field(default_factory=lambda: np.zeros(3))
    imu_acc_mps2: np.ndarray = field(default_factory=lambda: np.array([0.0, 0.0, 9.81]))
    motor_temperature_c: np.ndarray = field(default_factory=_zeros)
    mode_machine: int = 5
    tick: int = 0
    wireless_remote: bytes = b""
    battery_v: float | None = None
    """Battery voltage, where the link reports one (None: the G1's LowState_ carries none)."""
    # Ground truth, present only in simulation (None on the robot): for tests and logs.
    base_pos_w_m: np.ndarray | None = None
    base_linvel_w_mps: np.ndarray | None = None

    def validate(self) -> RobotState:
        """Raise InvalidStateError for a state no controller may act on."""
        for name in ("q_rad", "dq_radps", "tau_nm"):
            arr = getattr(self, name)
            if arr.shape != (NUM_JOINTS,):
                raise InvalidStateError(f"RobotState.{name} has shape {arr.shape}; expected ({NUM_JOINTS},)")
        quat = self.imu_quat_wxyz.tolist()  # small vectors as Python floats: cheaper than a numpy call each
        # One finite check over everything the controllers read (this runs every tick).
        if not math.isfinite(_sum(self.q_rad) + _sum(self.dq_radps) + sum(quat) + sum(self.imu_gyro_radps.tolist())
                             + sum(self.imu_acc_mps2.tolist())):
            bad = [n for n in ("q_rad", "dq_radps", "imu_quat_wxyz", "imu_gyro_radps", "imu_acc_mps2")
                   if not np.all(np.isfinite(getattr(self, n)))]
            raise InvalidStateError(f"RobotState.{', '.join(bad) or 'values'} contains NaN or inf")
        norm_sq = sum(c * c for c in quat)
        if abs(norm_sq - 1.0) > 2e-2:
            raise InvalidStateError(f"RobotState.imu_quat_wxyz has norm {norm_sq ** 0.5:.4f}; expected 1")
        return self


PHASE_LOCOMOTION = "locomotion"
PHASE_WHOLE_BODY = "whole_body"
PHASES = (PHASE_LOCOMOTION, PHASE_WHOLE_BODY)


@dataclass
class KinematicReference:
    """Whole-body target from the generator: root pose and twist, posture, named frame targets, contacts."""

    t_s: float = 0.0
    root_pos_w_m: np.ndarray = field(default_factory=lambda: np.zeros(3))
    root_quat_wxyz: np.ndarray = field(default_factory=lambda: np.array([1.0, 0.0, 0.0, 0.0]))
    root_linvel_h_mps: np.ndarray = field(default_factory=lambda: np.zeros(3))
    """The plan's root velocity in the heading frame (x forward, y left): what a walking tracker follows."""
    root_angvel_h_radps: np.ndarray = field(default_factory=lambda: np.zeros(3))
    """The plan's root angular velocity in the heading frame (z: the yaw rate)."""
    q_rad: np.ndarray = field(default_factory=_zeros)
    frame_targets_w: dict[str, np.ndarray] = field(default_factory=dict)
    """Frame name -> 7-vector (x, y, z, qw, qx, qy, qz) in the world frame."""
    contacts: np.ndarray = field(default_factory=lambda: np.ones(2, dtype=bool))
    """(left foot, right foot) in contact."""
    style: str = "default"
    upper_body_override: bool = False
    """True when the plan's waist and arm posture is meant to be followed; False leaves them to a
    balancing tracker's own judgement (a walking policy's own arm swing)."""
    pelvis_height_m: float | None = None
    """A pelvis height above the ground the tracker must hold (an operator's or a task's request);
    None leaves the height to the tracker (a walking policy's own)."""
    phase: str = "locomotion"
    """PHASE_LOCOMOTION: the plan walks or stands by a root velocity (a walking policy follows it);
    PHASE_WHOLE_BODY: root pose, joints and the contact schedule are all meant (a whole-body
    controller follows them: manipulation, stepping onto platforms, heights a walking policy
    cannot hold). The tracking layer hands over between its controllers by this."""

    hand_q_rad: np.ndarray | None = None
    """Dex3 finger angles (14, generator.skeleton.FINGER_JOINTS order) on a G1 with hands; None otherwise."""
    grasp_nm: np.ndarray = field(default_factory=lambda: np.zeros(2))
    """Per hand (left, right): the torque limit (N m) of the force-limited finger grasp the plan asks
    for (trackers/hands.py); 0: no grasp, the fingers follow hand_q_rad (or open)."""
    feasible_plan: JointReference | None = None
    """The tracker's reference when the generator made it feasible by construction (a sampled
    whole-body plan with exact joint velocities and hand forces; the default legs with a style's
    upper-body pose): the IK stage (g1_control/ik/stage.py) passes it on unchanged. None: the IK
    stage solves this reference. The generator owns it and refills it every tick; nobody
    downstream writes to it."""

    def set_from(self, j: JointReference) -> KinematicReference:
        """Root pose and twist, joints, contacts and phase from a joint reference (a whole-body
        plan sampled as both), and `j` itself as the feasible plan; returns self."""
        self.t_s = j.t_s
        self.root_pos_w_m[:] = j.root_pos_w_m
        self.root_quat_wxyz[:] = j.root_quat_wxyz
        self.root_linvel_h_mps[:] = j.root_linvel_h_mps
        self.root_angvel_h_radps[:] = j.root_angvel_h_radps
        self.q_rad[:] = j.q_rad
        self.contacts[:] = j.contacts
        self.phase = j.phase
        self.feasible_plan = j
        return self


@dataclass
class JointReference:
    """Feasible whole-body reference for the tracker."""

    t_s: float = 0.0
    q_rad: np.ndarray = field(default_factory=_zeros)
    dq_radps: np.ndarray = field(default_factory=_zeros)
    root_pos_w_m: np.ndarray = field(default_factory=lambda: np.zeros(3))
    root_quat_wxyz: np.ndarray = field(default_factory=lambda: np.array([1.0, 0.0, 0.0, 0.0]))
    root_linvel_h_mps: np.ndarray = field(default_factory=lambda: np.zeros(3))
    """Commanded root velocity in the heading frame (x forward, y left); locomotion trackers follow it."""
    root_angvel_h_radps: np.ndarray = field(default_factory=lambda: np.zeros(3))
    """Commanded root angular velocity in the heading frame (z: the yaw rate)."""
    contacts: np.ndarray = field(default_factory=lambda: np.ones(2, dtype=bool))
    upper_body_override: bool = False
    """When True, a balancing tracker takes waist/arm targets from q_rad instead of its own."""
    pelvis_height_m: float | None = None
    """The pelvis height to hold (KinematicReference.pelvis_height_m); None: the tracker's own."""
    phase: str = "locomotion"
    """KinematicReference.phase."""
    hand_forces_w_n: np.ndarray = field(default_factory=lambda: np.zeros((2, 3)))
    """Known forces a held object exerts on the (left, right) hand point, world axes (N): the
    reaction to the squeeze and the object's weight. A whole-body controller puts them in its
    dynamics, so its torques hold the object and its balance accounts for it."""
    hand_moments_w_nm: np.ndarray = field(default_factory=lambda: np.zeros((2, 3)))
    """Known moments a held object exerts about the (left, right) hand point, world axes (N m): its
    weight acting off the hand point (a bottle held in one hand, generator/goals/bottle.py)."""

    @property
    def holding(self) -> bool:
        """Whether a held object's forces are on the hands (the tracking layer's walk holding goes to its WBC;
        the WBC's gait then holds the pelvis, WbcConfig.walking_held_pelvis)."""
        return bool(self.hand_forces_w_n.any())

    def copy_from(self, src: JointReference) -> JointReference:
        """Copy every field of `src` into this reference's own arrays (no allocation); returns self."""
        self.t_s = src.t_s
        for name in ("q_rad", "dq_radps", "root_pos_w_m", "root_quat_wxyz", "root_linvel_h_mps",
                     "root_angvel_h_radps", "contacts", "hand_forces_w_n", "hand_moments_w_nm"):
            getattr(self, name)[:] = getattr(src, name)
        self.upper_body_override = src.upper_body_override
        self.pelvis_height_m = src.pelvis_height_m
        self.phase = src.phase
        return self


@dataclass
class EstimatedState:
    """The state estimator's output (g1_control/estimation/estimator.py), for trackers that close
    loops on the base's motion."""

    t_s: float = 0.0
    base_quat_wxyz: np.ndarray = field(default_factory=lambda: np.array([1.0, 0.0, 0.0, 0.0]))
    base_angvel_b_radps: np.ndarray = field(default_factory=lambda: np.zeros(3))
    base_linvel_w_mps: np.ndarray = field(default_factory=lambda: np.zeros(3))
    stance_weight: np.ndarray = field(default_factory=lambda: np.full(2, 0.5))
    yaw_rad: float = 0.0
    heading_velocity: np.ndarray = field(default_factory=lambda: np.zeros(3))
    """(vx, vy, wz): base linear velocity in the heading frame and the yaw rate."""
    pelvis_height_m: float | None = None
    """Pelvis height above the lower foot's sole (leg kinematics: the ground under a standing foot)."""


@dataclass(frozen=True)
class WorldPose:
    """The pelvis in a run's frame (estimation/pose.py: the start frame, x forward and y left of where
    the robot started; estimation/localiser.py: the launch file's scene frame)."""

    t_s: float
    x_m: float
    y_m: float
    z_m: float
    yaw_rad: float


NO_GOALS: Mapping[str, Any] = MappingProxyType({})
"""An empty, read-only goal table: what a generator without task goals reports."""


@dataclass(eq=False)
class ExecutionFeedback:
    """What execution reports back to the operator input: one record per loop, filled in place
    by the ControlLoop before every input poll (InputDevice.observe) and readable as
    `loop.feedback` (g1 deploy, run reports). Nothing here is copied per tick: the fields are
    the loop's own objects, valid until the next fill; keep a copy to keep a value.

    Only `truth` is the simulator's ground truth; everything else is what a robot has too."""

    t_s: float = 0.0
    """The loop's clock at the fill (simulated time in lockstep, monotonic on the robot)."""
    estimate: EstimatedState = field(default_factory=EstimatedState)
    """The state estimator's latest output (IMU yaw, leg-odometry velocity, pelvis height)."""
    state: RobotState | None = None
    """The robot's latest state as the backend reported it (joints, IMU: what a robot has; its base pose,
    where a simulator fills one, is for `truth` alone). None before the first read."""
    truth: RobotState | None = None
    """The latest robot state when the backend gives ground truth (its base_pos_w_m is set: a
    simulator); None on a robot. For judging outcomes, never for steering."""
    goal_status: Mapping[str, str] = field(default_factory=lambda: NO_GOALS)
    """goal_id -> "reached" | "failed" for the task goals the generator finished (Generator.goal_status)."""
    goal_messages: Mapping[str, str] = field(default_factory=lambda: NO_GOALS)
    """goal_id -> why the goal failed (Generator.goal_messages)."""
    phase: str = PHASE_LOCOMOTION
    """The generator's phase now (Generator.phase): PHASE_WHOLE_BODY while the execution layer holds the robot."""
    pose: WorldPose | None = None
    """The robot's own world pose estimate in the scene frame (leg odometry, fused with an external pose
    where one is configured: estimation/localiser.py); None where the loop runs no localiser."""


@dataclass
class MotorCommand:
    """Per-joint command for the robot's motor law:
    tau = tau_nm + kp * (q_rad - q) + kd * (dq_radps - dq), clipped to effort limits."""

    q_rad: np.ndarray = field(default_factory=_zeros)
    dq_radps: np.ndarray = field(default_factory=_zeros)
    kp: np.ndarray = field(default_factory=_zeros)
    kd: np.ndarray = field(default_factory=_zeros)
    tau_nm: np.ndarray = field(default_factory=_zeros)
    enable: np.ndarray = field(default_factory=lambda: np.ones(NUM_JOINTS, dtype=bool))

    @classmethod
    def damping(cls, kd: np.ndarray | float = 2.0) -> MotorCommand:
        """The fail-safe command: no stiffness, velocity damping only."""
        return cls(kd=np.broadcast_to(np.asarray(kd, dtype=float), (NUM_JOINTS,)).copy())

    def copy(self) -> MotorCommand:
        return MotorCommand(self.q_rad.copy(), self.dq_radps.copy(), self.kp.copy(),
                            self.kd.copy(), self.tau_nm.copy(), self.enable.copy())

    def hold_form(self) -> MotorCommand:
        """This command as a PD hold of its targets (a copy): the same q targets, gains and enables, no
        feedforward torque, a velocity target of zero (what a robot link resends once the command's
        life is up: hardware/link_backend.py)."""
        return MotorCommand(q_rad=self.q_rad.copy(), kp=self.kp.copy(), kd=self.kd.copy(), enable=self.enable.copy())

    def is_finite(self) -> bool:
        """No NaN or inf in any field. (One sum per field: this runs every tick. A sum that overflows
        to inf also reads as non-finite, which is the safe side for values near 1e308.)"""
        return bool(np.isfinite(self.q_rad.sum() + self.dq_radps.sum() + self.kp.sum() + self.kd.sum()
                                + self.tau_nm.sum()))


NUM_HAND_MOTORS = dex3.NUM_MOTORS
"""Motors of one Dex3-1 hand (g1_control/robot/dex3.py names them)."""


def _hand_zeros() -> np.ndarray:
    return np.zeros(NUM_HAND_MOTORS)


@dataclass
class FingerCommand:
    """One Dex3-1 hand's command, (7,) per field in the hand's motor order, same motor law as
    MotorCommand: tau = tau_nm + kp * (q_rad - q) + kd * (dq_radps - dq), clipped to the motor's effort."""

    q_rad: np.ndarray = field(default_factory=_hand_zeros)
    dq_radps: np.ndarray = field(default_factory=_hand_zeros)
    kp: np.ndarray = field(default_factory=_hand_zeros)
    kd: np.ndarray = field(default_factory=_hand_zeros)
    tau_nm: np.ndarray = field(default_factory=_hand_zeros)
    enable: np.ndarray = field(default_factory=lambda: np.ones(NUM_HAND_MOTORS, dtype=bool))

    @classmethod
    def damping(cls, kd: float = dex3.DAMPING_KD) -> FingerCommand:
        """The fail-safe command for a hand: no stiffness, velocity damping only."""
        return cls(kd=np.full(NUM_HAND_MOTORS, float(kd)))

    def copy(self) -> FingerCommand:
        return FingerCommand(self.q_rad.copy(), self.dq_radps.copy(), self.kp.copy(), self.kd.copy(),
                             self.tau_nm.copy(), self.enable.copy())

    def is_finite(self) -> bool:
        return bool(np.isfinite(self.q_rad.sum() + self.dq_radps.sum() + self.kp.sum() + self.kd.sum()
                                + self.tau_nm.sum()))

    @property
    def is_damping(self) -> bool:
        """kp 0 and kd > 0 on every motor."""
        return bool(np.all(self.kp == 0.0) and np.all(self.kd > 0.0))


@dataclass
class FingerState:
    """What one Dex3-1 hand reports (HandState_), (7,) per motor field in the hand's motor order."""

    q_rad: np.ndarray = field(default_factory=_hand_zeros)
    dq_radps: np.ndarray = field(default_factory=_hand_zeros)
    tau_nm: np.ndarray = field(default_factory=_hand_zeros)
    """The motors' estimated torque (tau_est): what a force-limited grasp watches."""
    temperature_c: np.ndarray = field(default_factory=_hand_zeros)
    """The hotter of each motor's two sensors."""
    motor_enabled: np.ndarray = field(default_factory=lambda: np.zeros(NUM_HAND_MOTORS, dtype=bool))
    power_v: float = 0.0
    power_a: float = 0.0
    error: tuple[int, int] = (0, 0)
    t_s: float = 0.0
    """time.monotonic() when the host received it."""
