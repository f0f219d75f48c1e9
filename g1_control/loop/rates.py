"""The loop's stage rates: one dataclass for launch files and the loop alike."""

from __future__ import annotations

from dataclasses import dataclass

from g1_control.errors import LaunchFileError


@dataclass
class LoopRates:
    lowlevel_hz: float = 500.0
    """Base tick: the latest motor command is resent every tick."""
    tracker_hz: float = 50.0
    """Generator, retargeter, tracker and safety filter."""
    input_hz: float = 100.0
    estimator_hz: float = 100.0

    def validate(self, where: str = "rates") -> None:
        if not 0 < self.lowlevel_hz <= 10_000:
            raise LaunchFileError(f"{where}.lowlevel_hz: {self.lowlevel_hz} Hz must be > 0 (and at most 10000): "
                                  "the base tick of the loop")
        for name in ("tracker_hz", "input_hz", "estimator_hz"):
            rate = getattr(self, name)
            ratio = self.lowlevel_hz / rate if rate > 0 else 0
            if rate <= 0 or abs(ratio - round(ratio)) > 1e-9:
                raise LaunchFileError(f"{where}.{name}: {rate} Hz must divide the low-level rate "
                                      f"{self.lowlevel_hz} Hz into a whole number of ticks")
