"""Plain data passed between the stages of one control tick.

Arrays are float64 numpy arrays in the robot's joint order (g1_control.robot.g1.JOINT_NAMES);
units are in the field names. Quaternions are (w, x, y, z). "_w" is the world frame, "_b" the
base (pelvis) frame, "_h" the heading frame (the world turned by the base's yaw: x forward along
the ground, y left, z up). Nothing here does I/O or math beyond validation.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from g1_control.errors import InvalidCommandError, InvalidStateError
from g1_control.robot.g1 import NUM_JOINTS


def _zeros() -> np.ndarray:
    return np.zeros(NUM_JOINTS)


BUTTONS = frozenset(
    {"start", "stop", "estop", "run", "style_next", "style_prev", "policy_switch", "damp"}
)
"""Operator buttons a Command may carry (edges: present on the tick they were pressed)."""


@dataclass
class EffectorGoal:
    """Put a named robot frame at a world point (optionally by time t_s from now)."""

    frame: str
    pos_w_m: np.ndarray
    t_s: float | None = None


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
    buttons: frozenset[str] = frozenset()

    def validate(self) -> Command:
        """Raise InvalidCommandError naming the first bad field; return self when fine."""
        for name in ("vx_mps", "vy_mps", "wz_radps", "heading_rad", "pelvis_height_m"):
            value = getattr(self, name)
            if value is not None and not np.isfinite(value):
                raise InvalidCommandError(f"Command.{name} is {value}; it must be a finite number")
        for goal in self.goals:
            pos = np.asarray(goal.pos_w_m, dtype=float)
            if pos.shape != (3,) or not np.all(np.isfinite(pos)):
                raise InvalidCommandError(
                    f"Command goal for frame '{goal.frame}' has position {goal.pos_w_m!r}; "
                    "it must be 3 finite numbers"
                )
        unknown = set(self.buttons) - BUTTONS
        if unknown:
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
    # Ground truth, present only in simulation (None on the robot): for tests and logs.
    base_pos_w_m: np.ndarray | None = None
    base_linvel_w_mps: np.ndarray | None = None

    def validate(self) -> RobotState:
        """Raise InvalidStateError for a state no controller may act on."""
        for name in ("q_rad", "dq_radps", "tau_nm"):
            arr = getattr(self, name)
            if arr.shape != (NUM_JOINTS,):
                raise InvalidStateError(f"RobotState.{name} has shape {arr.shape}; expected ({NUM_JOINTS},)")
        quat = self.imu_quat_wxyz
        # One finite check over everything the controllers read (this runs every tick).
        if not np.isfinite(self.q_rad.sum() + self.dq_radps.sum() + quat.sum() + self.imu_gyro_radps.sum()
                           + self.imu_acc_mps2.sum()):
            bad = [n for n in ("q_rad", "dq_radps", "imu_quat_wxyz", "imu_gyro_radps", "imu_acc_mps2")
                   if not np.all(np.isfinite(getattr(self, n)))]
            raise InvalidStateError(f"RobotState.{', '.join(bad) or 'values'} contains NaN or inf")
        norm_sq = float(quat @ quat)
        if abs(norm_sq - 1.0) > 2e-2:
            raise InvalidStateError(f"RobotState.imu_quat_wxyz has norm {norm_sq ** 0.5:.4f}; expected 1")
        return self


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
    hand_q_rad: np.ndarray | None = None
    """Dex3 finger angles (14, generator.skeleton.FINGER_JOINTS order) on a G1 with hands; None otherwise."""


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

    def is_finite(self) -> bool:
        """No NaN or inf in any field. (One sum per field: this runs every tick. A sum that overflows
        to inf also reads as non-finite, which is the safe side for values near 1e308.)"""
        return bool(np.isfinite(self.q_rad.sum() + self.dq_radps.sum() + self.kp.sum() + self.kd.sum()
                                + self.tau_nm.sum()))
