"""SafetyConfig: every threshold of the runtime safety layer, in one validated dataclass."""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

from g1_control.errors import SafetyConfigError


@dataclass(frozen=True)
class SafetyConfig:
    stale_state_s: float = 0.05
    """Damp when the newest state is older than this (SONIC's deploy allows 0.5 s; 25 robot ticks is plenty)."""
    max_tilt_rad: float = 1.0
    """Damp when the pelvis z axis leans further than this from vertical (a fall)."""
    overspeed_factor: float = 1.0
    """Damp when any |dq| exceeds this times the joint's velocity limit."""
    max_motor_temperature_c: float = 90.0
    """Damp when any motor reports a hotter winding/case (both sensors are checked)."""
    crc_burst_count: int = 5
    """Damp on this many bad-CRC states within crc_burst_window_s (a lone bad sample is only counted)."""
    crc_burst_window_s: float = 0.1
    overrun_burst_count: int = 5
    """Damp on this many control-loop deadline overruns within overrun_window_s."""
    overrun_window_s: float = 1.0
    input_zero_velocity_s: float = 0.2
    """With no fresh operator input for this long, velocity commands are zeroed (the robot stops)."""
    input_lost_s: float = 1.0
    """With no fresh operator input for this long, damp (armed once the first input arrived)."""
    position_margin_rad: float = 0.0
    """Position targets are kept this far inside the joint limits."""
    max_kp: float = 1000.0
    max_kd: float = 100.0
    damping_kd: float = 2.0
    """kd of the fail-safe damping command (kp 0)."""

    def __post_init__(self) -> None:
        for f in fields(self):
            value = getattr(self, f.name)
            if not isinstance(value, (int, float)) or isinstance(value, bool) or not math.isfinite(value):
                raise SafetyConfigError(f"SafetyConfig.{f.name} is {value!r}; it must be a finite number")
            if value < 0:
                raise SafetyConfigError(f"SafetyConfig.{f.name} is {value}; it must not be negative")
        for name in ("stale_state_s", "max_tilt_rad", "overspeed_factor", "crc_burst_window_s",
                     "overrun_window_s", "damping_kd"):
            if getattr(self, name) == 0:
                raise SafetyConfigError(f"SafetyConfig.{name} is 0; it must be positive")
        for name in ("crc_burst_count", "overrun_burst_count"):
            if int(getattr(self, name)) != getattr(self, name) or getattr(self, name) < 1:
                raise SafetyConfigError(f"SafetyConfig.{name} is {getattr(self, name)}; it must be a whole number >= 1")
        if self.input_lost_s < self.input_zero_velocity_s:
            raise SafetyConfigError(
                f"SafetyConfig.input_lost_s ({self.input_lost_s}) must not be shorter than "
                f"input_zero_velocity_s ({self.input_zero_velocity_s}): the robot stops before it damps")
