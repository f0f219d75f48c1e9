"""Turn a stream of InputSnapshots into Commands: the stateful half of the mapping.

Per poll: clamp and count bad axis values, detect button/chord edges, step keyboard virtual axes,
shape (deadzone, expo), scale to the tracker's command limits and the speed trigger, slew-limit,
and clamp. E-stop, damp and stop zero the velocity at once (no slew: stopping must not wait).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from g1_control.teleop.layouts import STICK
from g1_control.teleop.mapping import MappingConfig
from g1_control.teleop.snapshot import InputSnapshot
from g1_control.types import BUTTONS, Button, Command, CommandLimits

_STOPPING_ACTIONS = frozenset({Button.ESTOP, Button.DAMP, Button.STOP, "zero_velocity"})


@dataclass
class MapperStats:
    """Counters the operator display and logs can show."""

    nan_axis_values: int = 0
    """Axis samples that were NaN or infinite (read as the axis at rest)."""
    clamped_axis_values: int = 0
    """Axis samples outside the axis's range (clamped to it)."""
    actions: int = 0


class CommandMapper:
    """Stateful mapping from one device's snapshots to Commands."""

    def __init__(self, config: MappingConfig, limits: CommandLimits | None = None) -> None:
        self.config = config
        self.limits = limits or CommandLimits()
        self.stats = MapperStats()
        self._chords = sorted(config.buttons.items(), key=lambda item: -len(item[0]))
        self._virtual = {name: 0.0 for name in config.layout.axes} if config.layout.key_axes else {}
        self._vel = [0.0, 0.0, 0.0]  # vx, vy, wz after slew
        self._heading_rad = 0.0
        self._style_index = 0
        self._prev_held: frozenset[str] = frozenset()
        self._last_t_s: float | None = None

    @property
    def style(self) -> str:
        return self.config.styles[self._style_index]

    def reset_heading(self, heading_rad: float = 0.0) -> None:
        self._heading_rad = float(heading_rad)

    def lost_command(self) -> Command:
        """The command of a lost device: stand still and damp (repeated every poll, a level the
        safety layer cannot miss, not an edge). Velocity and virtual axes are zeroed so nothing
        resumes by itself if polling continues."""
        self._vel = [0.0, 0.0, 0.0]
        for name in self._virtual:
            self._virtual[name] = 0.0
        heading = self._heading_rad if self.config.yaw_mode == "heading" else None
        return Command(heading_rad=heading, style=self.style, buttons=frozenset({Button.DAMP}))

    # -- one poll ---------------------------------------------------------------------------
    def update(self, snapshot: InputSnapshot, t_s: float) -> Command:
        dt_s = 0.0 if self._last_t_s is None else max(0.0, t_s - self._last_t_s)
        self._last_t_s = t_s
        actions = self._actions(snapshot)
        self._step_virtual_axes(snapshot.pressed)

        stop_now = bool(actions & _STOPPING_ACTIONS)
        if stop_now:
            for name in self._virtual:
                if self.config.layout.axes[name] == STICK:
                    self._virtual[name] = 0.0
        if Button.STYLE_NEXT in actions:
            self._style_index = (self._style_index + 1) % len(self.config.styles)
        if Button.STYLE_PREV in actions:
            self._style_index = (self._style_index - 1) % len(self.config.styles)

        scale = 1.0
        if "speed_scale" in self.config.axes:
            low, high = self.config.speed_scale_range
            scale = low + (high - low) * self._shaped("speed_scale", snapshot)
        targets = []
        for field, limits in (("vx", self.limits.vx_mps), ("vy", self.limits.vy_mps), ("wz", self.limits.wz_radps)):
            x = self._shaped(field, snapshot) if field in self.config.axes else 0.0
            # Each direction reaches its own limit: vx may be [-0.5, 1.0].
            targets.append(scale * x * (limits[1] if x > 0 else -limits[0]))

        for i, field in enumerate(("vx", "vy", "wz")):
            if stop_now:
                self._vel[i] = 0.0
                continue
            rate = self.config.slew_rate.get(field)
            if rate is None:
                self._vel[i] = targets[i]
            else:
                step = rate * dt_s
                self._vel[i] += min(step, max(-step, targets[i] - self._vel[i]))
        vx = _clip(self._vel[0], self.limits.vx_mps)
        vy = _clip(self._vel[1], self.limits.vy_mps)
        wz = _clip(self._vel[2], self.limits.wz_radps)

        heading = None
        if self.config.yaw_mode == "heading":
            self._heading_rad = math.remainder(self._heading_rad + wz * dt_s, math.tau)
            heading = self._heading_rad
        height = None
        if "pelvis_height" in self.config.axes:
            low, high = self.limits.pelvis_height_m
            height = high - (high - low) * self._shaped("pelvis_height", snapshot)
        return Command(vx_mps=vx, vy_mps=vy, wz_radps=wz, heading_rad=heading, style=self.style,
                       pelvis_height_m=height, buttons=frozenset(actions & BUTTONS))

    # -- parts ------------------------------------------------------------------------------
    def _raw_axis(self, name: str, snapshot: InputSnapshot) -> float:
        """The axis value, NaN read as rest and out-of-range clamped, both counted."""
        if name in self._virtual:
            return self._virtual[name]
        value = snapshot.axes.get(name, 0.0)
        if not math.isfinite(value):
            self.stats.nan_axis_values += 1
            return 0.0
        low = -1.0 if self.config.layout.axes[name] == STICK else 0.0
        if value < low or value > 1.0:
            self.stats.clamped_axis_values += 1
            value = min(1.0, max(low, value))
        return value

    def _shaped(self, field: str, snapshot: InputSnapshot) -> float:
        binding = self.config.axes[field]
        return binding.shape(self._raw_axis(binding.axis, snapshot))

    def _actions(self, snapshot: InputSnapshot) -> set[str]:
        """Actions whose chord became complete in this interval. When a chord and a smaller one
        inside it complete together (L1 then R1 pressed within one poll, or A pressed while L1 is
        held with 'L1+A' bound), only the larger one fires."""
        pressed = set(snapshot.pressed)
        down = snapshot.held | pressed
        new = (snapshot.held - self._prev_held) | pressed
        self._prev_held = snapshot.held
        if not new:
            return set()
        fired: list[frozenset[str]] = []
        actions: set[str] = set()
        for chord, action in self._chords:  # largest chords first
            if chord <= down and chord & new and not any(chord < big for big in fired):
                fired.append(chord)
                actions.add(action)
        self.stats.actions += len(actions)
        return actions

    def _step_virtual_axes(self, pressed: tuple[str, ...]) -> None:
        for key in pressed:
            binding = self.config.key_axes.get(key)
            if binding is None:
                continue
            axis, step = binding
            low = -1.0 if self.config.layout.axes[axis] == STICK else 0.0
            self._virtual[axis] = min(1.0, max(low, round(self._virtual[axis] + step, 9)))


def _clip(value: float, limits: tuple[float, float]) -> float:
    return min(limits[1], max(limits[0], value))
