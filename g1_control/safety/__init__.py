"""Runtime safety layer: limits, watchdogs and the one-way switch to damping (sim and robot alike)."""

from g1_control.safety.config import SafetyConfig
from g1_control.safety.events import SafetyEvent, SafetyEventKind
from g1_control.safety.filter import ClampCounts, SafetyFilter
from g1_control.safety.guarded_backend import GuardedBackend, install_signal_damping

__all__ = ["ClampCounts", "GuardedBackend", "SafetyConfig", "SafetyEvent", "SafetyEventKind", "SafetyFilter",
           "install_signal_damping"]
