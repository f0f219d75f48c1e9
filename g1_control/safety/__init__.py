"""Runtime safety layer: limits, watchdogs and the one-way switch to damping (sim and robot alike)."""

from g1_control.safety.config import SafetyConfig
from g1_control.safety.events import SafetyEvent, SafetyEventKind
from g1_control.safety.filter import ClampCounts, SafetyFilter, tilt_rad

__all__ = ["ClampCounts", "SafetyConfig", "SafetyEvent", "SafetyEventKind", "SafetyFilter", "tilt_rad"]
