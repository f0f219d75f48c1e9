"""How one device's sticks, triggers and buttons become a Command: the validated configuration.

Written in the launch file under the device, e.g.

    input:
      type: gamepad
      path: /dev/input/event5
      mapping:
        axes:
          vx: {axis: left_y, invert: true, deadzone: 0.1, expo: 0.3}
        buttons: {A: run, B: stop, "LB+RB": estop}
        slew_rate: {vx: 1.0}

Sections not written keep the device's default (layouts.py). `axes` merges field by field (set a
field to null to unbind it); `buttons` and `key_axes` replace the default section entirely, so
no default binding lingers on a button the launch file meant for something else.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

from g1_control.errors import LaunchFileError
from g1_control.teleop.layouts import LAYOUTS, STICK, TRIGGER, DeviceLayout
from g1_control.types import BUTTONS

AXIS_FIELDS = {"vx": STICK, "vy": STICK, "wz": STICK, "speed_scale": TRIGGER, "pelvis_height": TRIGGER}
"""Command fields an axis can drive, and the kind of axis each expects."""
SLEW_FIELDS = ("vx", "vy", "wz")
GOAL_ACTIONS = {"pick": "pick", "place": "place", "step_up": "step_up", "step_down": "step_down"}
"""Actions that start a task goal (types.TaskGoal) against the scene: pick the box in front, set
the held box down in front (on a table or platform there, else on the floor), step onto the
platform in front, step back down. Executed by tracker.type layer (g1_control/generator/goals/)."""
LINE_ACTION = "instruction"
"""Keyboard: enter line mode to type an English instruction (teleop/keyboard.py); stops the robot."""
ACTIONS = BUTTONS | {"zero_velocity", LINE_ACTION} | set(GOAL_ACTIONS)
"""What a button can do: every Command button, zero_velocity (handled inside the mapping), goals and,
on a keyboard, instruction (line mode)."""
YAW_MODES = ("rate", "heading")


@dataclass(frozen=True)
class AxisBinding:
    """One device axis driving one command field.

    deadzone: fraction of travel around rest that reads as 0; the rest is rescaled so the output
      is continuous (just outside the deadzone gives just above 0, full travel gives 1).
    expo: blend between linear and cubic response, out = (1 - expo) x + expo x^3, as RC
      transmitters do: fine control near centre, full range at the end.
    """

    axis: str
    invert: bool = False
    deadzone: float = 0.0
    expo: float = 0.0

    def shape(self, x: float) -> float:
        """Deadzone and expo on a clamped axis value (sign kept; |x| <= 1)."""
        if self.invert:
            x = -x
        magnitude = abs(x)
        if magnitude <= self.deadzone:
            return 0.0
        magnitude = (magnitude - self.deadzone) / (1.0 - self.deadzone)
        magnitude = (1.0 - self.expo) * magnitude + self.expo * magnitude**3
        return math.copysign(magnitude, x)


@dataclass(frozen=True)
class MappingConfig:
    layout: DeviceLayout
    axes: dict[str, AxisBinding] = field(default_factory=dict)
    """Command field (AXIS_FIELDS) -> binding; absent fields are not driven."""
    buttons: dict[frozenset[str], str] = field(default_factory=dict)
    """Chord (one or more button names, all held) -> action (ACTIONS)."""
    key_axes: dict[str, tuple[str, float]] = field(default_factory=dict)
    """Keyboard only: key -> (virtual axis, step per press)."""
    slew_rate: dict[str, float] = field(default_factory=dict)
    """Field -> max change per second (m/s^2 for vx/vy, rad/s^2 for wz); absent = unlimited."""
    yaw_mode: str = "rate"
    """'rate': the yaw axis commands wz. 'heading': it also steers Command.heading_rad, the
    integral of wz from 0 at start (relative to the robot's heading when teleop began)."""
    speed_scale_range: tuple[float, float] = (0.5, 1.0)
    """Scale on velocities with the speed trigger released and fully pulled (1.0 if unbound)."""
    styles: tuple[str, ...] = ("default",)
    """Styles that style_next / style_prev cycle through; the first is the starting style."""

    @classmethod
    def default(cls, device_type: str) -> MappingConfig:
        return cls.from_dict(None, f"default mapping of {device_type}", layout=LAYOUTS[device_type])

    @classmethod
    def from_dict(cls, d: Mapping[str, Any] | None, where: str, *, layout: DeviceLayout) -> MappingConfig:
        """Validate a launch-file mapping for a device with `layout`.

        Raises LaunchFileError naming the key path (`where` + ".buttons.A") of the first problem.
        """
        if d is None:
            d = {}
        if not isinstance(d, Mapping):
            raise LaunchFileError(f"{where} is {type(d).__name__}; expected a mapping")
        sections = ("axes", "buttons", "key_axes", "slew_rate", "yaw_mode", "speed_scale_range", "styles")
        for key in d:
            if key not in sections:
                raise LaunchFileError(f"{where}.{key} is not a mapping section; known: {', '.join(sections)}")
        if "key_axes" in d and not layout.key_axes:
            raise LaunchFileError(f"{where}.key_axes: only a keyboard has key_axes, this is a {layout.kind}")
        default = layout.default_mapping

        axes_spec = dict(_mapping(default.get("axes", {}), f"{where}.axes"))
        axes_spec.update(_mapping(d.get("axes", {}), f"{where}.axes"))
        axes = {}
        for name, spec in axes_spec.items():
            if spec is None:
                continue
            axes[name] = _axis_binding(spec, name, f"{where}.axes.{name}", layout)

        buttons_spec = d["buttons"] if "buttons" in d else default.get("buttons", {})
        buttons = _buttons(_mapping(buttons_spec, f"{where}.buttons"), f"{where}.buttons", layout)

        key_axes = {}
        if layout.key_axes:
            spec = d["key_axes"] if "key_axes" in d else default.get("key_axes", {})
            key_axes = _key_axes(_mapping(spec, f"{where}.key_axes"), f"{where}.key_axes", layout)
            for key in key_axes:
                if frozenset([key]) in buttons:
                    raise LaunchFileError(
                        f"{where}.key_axes.{key}: key '{key}' is also bound to "
                        f"'{buttons[frozenset([key])]}' in {where}.buttons; a key does one thing"
                    )

        slew_spec = dict(_mapping(default.get("slew_rate", {}), f"{where}.slew_rate"))
        slew_spec.update(_mapping(d.get("slew_rate", {}), f"{where}.slew_rate"))
        slew_rate = {}
        for name, value in slew_spec.items():
            if name not in SLEW_FIELDS:
                raise LaunchFileError(f"{where}.slew_rate.{name} is not a slewed field; known: {', '.join(SLEW_FIELDS)}")
            if value is None:
                continue
            slew_rate[name] = _number(value, f"{where}.slew_rate.{name}", low=0.0, low_open=True)

        yaw_mode = d.get("yaw_mode", default.get("yaw_mode", "rate"))
        if yaw_mode not in YAW_MODES:
            raise LaunchFileError(f"{where}.yaw_mode is {yaw_mode!r}; expected one of {', '.join(YAW_MODES)}")

        scale = d.get("speed_scale_range", default.get("speed_scale_range", [0.5, 1.0]))
        if not isinstance(scale, (list, tuple)) or len(scale) != 2:
            raise LaunchFileError(f"{where}.speed_scale_range is {scale!r}; expected [low, high]")
        low = _number(scale[0], f"{where}.speed_scale_range[0]", low=0.0)
        high = _number(scale[1], f"{where}.speed_scale_range[1]", low=0.0, high=1.0)
        if low > high:
            raise LaunchFileError(f"{where}.speed_scale_range is {list(scale)}; expected low <= high")

        styles = d.get("styles", default.get("styles", ["default"]))
        if (
            not isinstance(styles, (list, tuple))
            or not styles
            or not all(isinstance(s, str) and s for s in styles)
        ):
            raise LaunchFileError(f"{where}.styles is {styles!r}; expected a non-empty list of style names")
        if len(set(styles)) != len(styles):
            raise LaunchFileError(f"{where}.styles lists a style twice: {list(styles)}")

        return cls(layout, axes, buttons, key_axes, slew_rate, yaw_mode, (low, high), tuple(styles))


def _mapping(value: Any, where: str) -> Mapping[str, Any]:
    if not isinstance(value, Mapping):
        raise LaunchFileError(f"{where} is {type(value).__name__}; expected a mapping")
    for key in value:
        if not isinstance(key, str):
            raise LaunchFileError(f"{where} has key {key!r} ({type(key).__name__}); keys must be names (strings)")
    return value


def _number(value: Any, where: str, *, low: float | None = None, high: float | None = None,
            low_open: bool = False, high_open: bool = False) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise LaunchFileError(f"{where} is {value!r}; expected a finite number")
    value = float(value)
    if low is not None and (value < low or (low_open and value == low)):
        raise LaunchFileError(f"{where} is {value}; expected {'>' if low_open else '>='} {low}")
    if high is not None and (value > high or (high_open and value == high)):
        raise LaunchFileError(f"{where} is {value}; expected {'<' if high_open else '<='} {high}")
    return value


def _axis_binding(spec: Any, name: str, where: str, layout: DeviceLayout) -> AxisBinding:
    if name not in AXIS_FIELDS:
        raise LaunchFileError(f"{where}: '{name}' is not a command field an axis can drive; "
                              f"known: {', '.join(AXIS_FIELDS)}")
    if isinstance(spec, str):
        spec = {"axis": spec}
    spec = _mapping(spec, where)
    allowed = ("axis", "invert", "deadzone", "expo")
    for key in spec:
        if key not in allowed:
            raise LaunchFileError(f"{where}.{key} is not an axis setting; known: {', '.join(allowed)}")
    axis = spec.get("axis")
    if axis not in layout.axes:
        raise LaunchFileError(f"{where}.axis is {axis!r}, not an axis of a {layout.kind}; "
                              f"known: {', '.join(sorted(layout.axes))}")
    if layout.axes[axis] != AXIS_FIELDS[name]:
        raise LaunchFileError(f"{where}.axis: {name} needs a {AXIS_FIELDS[name]} but '{axis}' is a {layout.axes[axis]}")
    invert = spec.get("invert", False)
    if not isinstance(invert, bool):
        raise LaunchFileError(f"{where}.invert is {invert!r}; expected true or false")
    deadzone = _number(spec.get("deadzone", 0.0), f"{where}.deadzone", low=0.0, high=1.0, high_open=True)
    expo = _number(spec.get("expo", 0.0), f"{where}.expo", low=0.0, high=1.0)
    return AxisBinding(axis, invert, deadzone, expo)


def parse_chord(name: str, where: str, layout: DeviceLayout) -> frozenset[str]:
    """'L1+R1' -> {'L1', 'R1'} on devices with chords; a keyboard key name as is."""
    # A lone '+' is a keyboard key, never a chord separator.
    parts = name.split("+") if layout.chords and name != "+" else [name]
    if any(not p for p in parts):
        raise LaunchFileError(f"{where}.{name}: empty button name in chord '{name}'")
    for part in parts:
        if part not in layout.buttons:
            hint = ""
            if layout.kind == "keyboard" and part.lower() in layout.buttons:
                hint = f" (keys are named in lower case: '{part.lower()}')"
            elif layout.kind == "keyboard":
                hint = " (a keyboard has no chords)" if "+" in part and not part.startswith("ctrl+") else ""
            known = ", ".join(sorted(layout.buttons)) if layout.kind != "keyboard" else \
                "one printable character or " + ", ".join(sorted(k for k in layout.buttons if len(k) > 1))
            raise LaunchFileError(f"{where}.{name}: '{part}' is not a button of a {layout.kind}{hint}; known: {known}")
    if len(set(parts)) != len(parts):
        raise LaunchFileError(f"{where}.{name}: chord '{name}' names a button twice")
    return frozenset(parts)


def _buttons(spec: Mapping[str, Any], where: str, layout: DeviceLayout) -> dict[frozenset[str], str]:
    buttons: dict[frozenset[str], str] = {}
    spelled: dict[frozenset[str], str] = {}
    for name, action in spec.items():
        chord = parse_chord(name, where, layout)
        if isinstance(action, (list, tuple)):
            raise LaunchFileError(f"{where}.{name}: two actions bound to one button ({list(action)}); bind one")
        if action not in ACTIONS:
            raise LaunchFileError(f"{where}.{name} is {action!r}, not an action; known: {', '.join(sorted(ACTIONS))}")
        if action == LINE_ACTION and (layout.kind != "keyboard" or len(chord) != 1):
            raise LaunchFileError(f"{where}.{name}: '{LINE_ACTION}' (typing a line) is a single keyboard key")
        if chord in buttons:
            raise LaunchFileError(
                f"{where}.{name}: two actions bound to one button: '{spelled[chord]}' is already "
                f"'{buttons[chord]}', '{name}' would be '{action}'"
            )
        buttons[chord] = action
        spelled[chord] = name
    return buttons


def _key_axes(spec: Mapping[str, Any], where: str, layout: DeviceLayout) -> dict[str, tuple[str, float]]:
    out = {}
    for key, value in spec.items():
        parse_chord(key, where, layout)
        if not isinstance(value, (list, tuple)) or len(value) != 2:
            raise LaunchFileError(f"{where}.{key} is {value!r}; expected [axis, step]")
        axis, step = value
        if axis not in layout.axes:
            raise LaunchFileError(f"{where}.{key}: '{axis}' is not an axis of a {layout.kind}; "
                                  f"known: {', '.join(sorted(layout.axes))}")
        step = _number(step, f"{where}.{key}[1]", low=-1.0, high=1.0)
        if step == 0.0:
            raise LaunchFileError(f"{where}.{key}[1] is 0; a key that moves nothing is a mistake")
        out[key] = (axis, step)
    return out
