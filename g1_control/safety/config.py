"""SafetyConfig: every threshold of the runtime safety layer, in one validated dataclass."""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

from g1_control.errors import SafetyConfigError
from g1_control.robot import g1

MAX_KP_CAP = 1000.0
"""The largest position-gain cap a SafetyConfig accepts (N m/rad): far above any G1 controller's
gains (Unitree's examples and the shipped policies stay below 300), far below a value that stops
being a cap."""
MAX_KD_CAP = 100.0
"""The largest velocity-gain cap a SafetyConfig accepts (N m s/rad)."""


@dataclass(frozen=True)
class SafetyConfig:
    stale_state_s: float = 0.05
    """Damp when the newest state is older than this (SONIC's deploy allows 0.5 s; 25 robot ticks is plenty)."""
    max_tilt_rad: float = 1.0
    """Damp when the pelvis z axis leans further than this from vertical (a fall); below pi (no tilt
    exceeds pi, so a larger limit could never fire)."""
    overspeed_factor: float = 1.0
    """Damp when any |dq| exceeds this times the joint's velocity limit."""
    max_motor_temperature_c: float = 90.0
    """Damp when any motor reports a hotter winding/case (both sensors are checked); at most the
    motors' rating (robot.g1.MOTOR_MAX_TEMPERATURE_C)."""
    crc_burst_count: int = 5
    """Damp on this many bad-CRC states within crc_burst_window_s (a lone bad sample is only counted)."""
    crc_burst_window_s: float = 0.1
    overrun_burst_count: int = 5
    """Damp on this many control-loop deadline overruns within overrun_window_s."""
    overrun_window_s: float = 1.0
    overrun_lateness_s: float = 0.0
    """A control-loop tick counts as an overrun when it finishes more than this late (0: any lateness)."""
    input_zero_velocity_s: float = 0.2
    """With no fresh operator input for this long, velocity commands are zeroed (the robot stops)."""
    input_lost_s: float = 1.0
    """With no fresh operator input for this long, damp (armed once the first input arrived)."""
    position_margin_rad: float = 0.0
    """Position targets are kept this far inside the joint limits."""
    max_kp: float = 1000.0
    """Position gains are clamped to this (N m/rad); at most MAX_KP_CAP."""
    max_kd: float = 100.0
    """Velocity gains are clamped to this (N m s/rad); at most MAX_KD_CAP."""
    damping_kd: float = 2.0
    """kd of the fail-safe damping command (kp 0); at most max_kd."""
    state_limit_margin_rad: float = 0.25
    """Damp when a joint reads further than this outside its limits (a sensor or decoding fault: the
    joint's mechanical stop is much closer)."""
    max_quat_norm_error: float = 0.1
    """Damp when the IMU quaternion's norm differs from 1 by more than this."""
    ik_hold_ticks: int = 3
    """While the IK finds no solution (even relaxed), the tracker keeps the last good reference for up
    to this many tracker ticks in a row (3: 60 ms at 50 Hz); the next failure in a row damps. 0: damp
    on the first failure. A whole number."""

    command_hold_ticks: float = 3.0
    """On a robot link, a motor command not renewed within this many tracker ticks (a stalled host) is
    resent in its hold form: the same position targets and gains, no feedforward torque, zero velocity
    target (hardware/link_backend.py). The whole-body controller's torque and velocity targets are
    meant for one tick; held through a 120 ms stall they threw a shoulder to 47 rad/s. 0: never (the
    last command streams as it is until a trip damps); otherwise at least 1.5 (a tick may come half a
    period late)."""

    def __post_init__(self) -> None:
        for f in fields(self):
            value = getattr(self, f.name)
            if not isinstance(value, (int, float)) or isinstance(value, bool) or not math.isfinite(value):
                raise SafetyConfigError(f"SafetyConfig.{f.name} is {value!r}; it must be a finite number")
            if value < 0:
                raise SafetyConfigError(f"SafetyConfig.{f.name} is {value}; it must not be negative")
        for name in ("stale_state_s", "max_tilt_rad", "overspeed_factor", "crc_burst_window_s",
                     "overrun_window_s", "damping_kd", "max_kp", "max_kd", "max_quat_norm_error"):
            if getattr(self, name) == 0:
                raise SafetyConfigError(f"SafetyConfig.{name} is 0; it must be positive")
        for name in ("crc_burst_count", "overrun_burst_count"):
            if int(getattr(self, name)) != getattr(self, name) or getattr(self, name) < 1:
                raise SafetyConfigError(f"SafetyConfig.{name} is {getattr(self, name)}; it must be a whole number >= 1")
        if int(self.ik_hold_ticks) != self.ik_hold_ticks:
            raise SafetyConfigError(f"SafetyConfig.ik_hold_ticks is {self.ik_hold_ticks}; it must be a whole number "
                                    ">= 0 (tracker ticks)")
        if 0 < self.command_hold_ticks < 1.5:
            raise SafetyConfigError(f"SafetyConfig.command_hold_ticks is {self.command_hold_ticks}; it must be 0 (never "
                                    "hold) or at least 1.5 tracker ticks (a tick may come half a period late, and a "
                                    "command must last until the next one)")
        if self.max_tilt_rad >= math.pi:
            raise SafetyConfigError(f"SafetyConfig.max_tilt_rad is {self.max_tilt_rad}; it must be below pi "
                                    f"({math.pi:.4f} rad): no tilt exceeds pi, so the tilt trip could never fire")
        if self.max_motor_temperature_c > g1.MOTOR_MAX_TEMPERATURE_C:
            raise SafetyConfigError(f"SafetyConfig.max_motor_temperature_c is {self.max_motor_temperature_c} °C; it may "
                                    f"be at most the motors' rating, {g1.MOTOR_MAX_TEMPERATURE_C:g} °C (a hotter "
                                    "threshold trips only after the damage)")
        if self.max_kp > MAX_KP_CAP:
            raise SafetyConfigError(f"SafetyConfig.max_kp is {self.max_kp}; the gain cap may be at most {MAX_KP_CAP:g}")
        if self.max_kd > MAX_KD_CAP:
            raise SafetyConfigError(f"SafetyConfig.max_kd is {self.max_kd}; the gain cap may be at most {MAX_KD_CAP:g}")
        if self.damping_kd > self.max_kd:
            raise SafetyConfigError(f"SafetyConfig.damping_kd ({self.damping_kd}) exceeds max_kd ({self.max_kd})")
        if self.input_lost_s < self.input_zero_velocity_s:
            raise SafetyConfigError(
                f"SafetyConfig.input_lost_s ({self.input_lost_s}) must not be shorter than "
                f"input_zero_velocity_s ({self.input_zero_velocity_s}): the robot stops before it damps")
