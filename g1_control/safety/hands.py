"""The safety layer for the Dex3-1 fingers: every finger command vetted like a joint command.

    hands = GuardedHands(Dex3HandLink("lo", 1))
    hands.write("right", command)      # clamped (limits, speed, gains, effort), or damping once tripped

What it does to each FingerCommand, per hand:
- NaN or inf anywhere: refused; the hands trip and damp (kp 0, kd > 0), latched until reset_trip();
- position targets kept inside the URDF's limits (less `position_margin_rad`);
- the target moves at most `max_speed_radps` times the time since the last command (the first
  command starts from the measured position), so a jump becomes a ramp;
- kp, kd clamped to `max_kp`, `max_kd`; feed-forward torque to the URDF's effort limit;
- the hand's state older than `stale_state_s`, never received, unchanged for `frozen_state_s`
  (samples arriving with identical contents), reading a finger position that is not finite, or
  reporting an error: trip, damp.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, fields
from typing import Protocol

import numpy as np

from g1_control.errors import SafetyConfigError
from g1_control.robot import dex3
from g1_control.types import FingerCommand, FingerState


class HandLink(Protocol):
    """What GuardedHands needs of a hand link (hardware/hand_link.py's Dex3HandLink)."""

    sides: tuple[dex3.Side, ...]
    damping_kd: float

    def write(self, side: dex3.Side, command: FingerCommand) -> None: ...

    def read(self, side: dex3.Side) -> FingerState | None: ...

    def damp(self, sides: tuple[dex3.Side, ...] | None = None) -> None: ...

    def last_change_s(self, side: dex3.Side) -> float: ...


@dataclass(frozen=True)
class HandSafetyConfig:
    position_margin_rad: float = 0.02
    """Targets are kept this far inside each finger's URDF limits."""
    max_speed_radps: float = 3.0
    """Fastest a finger's position target may move (the URDF allows 3.14 rad/s at thumb_0)."""
    max_kp: float = 5.0
    """Position gain cap (N m/rad): 5 turns a 0.28 rad error into the 1.4 N m a finger motor has."""
    max_kd: float = 0.5
    """Velocity gain cap (N m s/rad)."""
    stale_state_s: float = 0.25
    """Damp when the hand's newest state is older than this (25 samples at 100 Hz). Measured on a loaded
    2-core host (load 5.5), emulator and host in separate processes: gaps of up to 0.17 s between
    HandState_ samples; a finger motor's 1.4 N m does little harm in a quarter second."""
    frozen_state_s: float = 0.5
    """Damp when the hand's state has not changed for this long (samples arriving, contents frozen)."""

    def __post_init__(self) -> None:
        for f in fields(self):
            value = getattr(self, f.name)
            if not isinstance(value, (int, float)) or isinstance(value, bool) or not math.isfinite(value) or value < 0:
                raise SafetyConfigError(f"HandSafetyConfig.{f.name} is {value!r}; it must be a finite number >= 0")
        for name in ("max_speed_radps", "max_kp", "max_kd", "stale_state_s", "frozen_state_s"):
            if getattr(self, name) == 0:
                raise SafetyConfigError(f"HandSafetyConfig.{name} is 0; it must be positive")


class GuardedHands:
    def __init__(self, link: HandLink, config: HandSafetyConfig | None = None,
                 clock: Callable[[], float] = time.monotonic):
        self.link = link
        self.config = config or HandSafetyConfig()
        self.clock = clock
        self.tripped: str | None = None
        """Why the hands were damped (None: not tripped)."""
        self.events: list[tuple[float, str]] = []
        self._last: dict[str, tuple[float, np.ndarray]] = {}
        self._limits = {s: dex3.hand_limits(s) for s in link.sides}

    def write(self, side: dex3.Side, command: FingerCommand) -> FingerCommand:
        """Vet `command` for hand `side` and stream what passed; return what went out."""
        now = self.clock()
        if self.tripped is None:
            fault = self._fault(side, command, now)
            if fault is not None:
                self.trip(fault)
        if self.tripped is not None:
            return FingerCommand.damping(self.link.damping_kd)
        out = self.clamp(side, command, now)
        self.link.write(side, out)
        return out

    def clamp(self, side: dex3.Side, command: FingerCommand, now: float) -> FingerCommand:
        """`command` inside the limits (finite input assumed: write() refuses the rest)."""
        cfg, lim = self.config, self._limits[side]
        lo, hi = lim.q_min_rad + cfg.position_margin_rad, lim.q_max_rad - cfg.position_margin_rad
        q = np.clip(command.q_rad, lo, hi)
        last = self._last.get(side)
        if last is None:
            state = self.link.read(side)
            last = (now, np.clip(state.q_rad, lo, hi)) if state is not None else (now, q)
        step = cfg.max_speed_radps * max(0.0, now - last[0])
        q = np.clip(q, last[1] - step, last[1] + step)
        self._last[side] = (now, q.copy())
        return FingerCommand(
            q_rad=q, dq_radps=np.clip(command.dq_radps, -lim.velocity_radps, lim.velocity_radps),
            kp=np.clip(command.kp, 0.0, cfg.max_kp), kd=np.clip(command.kd, 0.0, cfg.max_kd),
            tau_nm=np.clip(command.tau_nm, -lim.effort_nm, lim.effort_nm), enable=command.enable.copy())

    def trip(self, reason: str) -> None:
        """Damp every hand now and refuse commands until reset_trip()."""
        if self.tripped is None:
            self.tripped = reason
            self.events.append((self.clock(), reason))
        self.link.damp()

    def reset_trip(self) -> None:
        self.tripped = None
        self._last.clear()

    def _fault(self, side: dex3.Side, command: FingerCommand, now: float) -> str | None:
        for name in ("q_rad", "dq_radps", "kp", "kd", "tau_nm", "enable"):
            if np.shape(getattr(command, name)) != (dex3.NUM_MOTORS,):
                return (f"{side} FingerCommand.{name} has shape {np.shape(getattr(command, name))}; "
                        f"expected ({dex3.NUM_MOTORS},)")
        if not command.is_finite():
            bad = [f"{f}[{dex3.FINGERS[i]}]" for f in ("q_rad", "dq_radps", "kp", "kd", "tau_nm")
                   for i in np.nonzero(~np.isfinite(getattr(command, f)))[0]]
            return f"{side} hand command is not finite ({', '.join(bad[:4])}); the fingers were damped"
        state = self.link.read(side)
        if state is None:
            return f"no state from the {side} hand yet; the fingers were damped"
        if not np.all(np.isfinite(state.q_rad)):  # the first command's ramp starts from this reading
            bad = [f"q_rad[{dex3.FINGERS[i]}]" for i in np.nonzero(~np.isfinite(state.q_rad))[0]]
            return f"the {side} hand reads no number ({', '.join(bad[:4])}); the fingers were damped"
        if now - state.t_s > self.config.stale_state_s:
            return (f"the {side} hand's state is {now - state.t_s:.2f} s old (limit "
                    f"{self.config.stale_state_s:.2f} s); the fingers were damped")
        unchanged_s = now - self.link.last_change_s(side)
        if unchanged_s > self.config.frozen_state_s:
            return (f"the {side} hand's state has not changed for {unchanged_s:.2f} s (limit "
                    f"{self.config.frozen_state_s:.2f} s): frozen; the fingers were damped")
        if any(state.error):
            return f"the {side} hand reports error {state.error[0]:#x}/{state.error[1]:#x}; the fingers were damped"
        return None
