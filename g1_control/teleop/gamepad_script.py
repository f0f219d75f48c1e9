"""A timed gamepad sequence turned into the kernel's evdev bytes, for driving the real gamepad
reader without a gamepad: scripted sim sessions, demos, and tests of the whole input path.

    - {t_s: 0.5, press: [start]}
    - {t_s: 0.7, release: [start]}
    - {t_s: 2.0, axes: {left_y: 0.8}}        # stick pushed 80 % toward the user: robot walks back
    - {t_s: 5.0, axes: {left_y: 0.0}}

Axis values are what the gamepad reports, normalized (sticks -1..1 with evdev's sign: left_y
negative is forward; triggers 0..1), so the mapping under test does the same work as with a pad.
A GamepadScriptFeeder writes each step into a FIFO when the caller's clock (sim time in
lockstep) reaches it; an EvdevGamepad opened on feeder.path reads them as from /dev/input.
"""

from __future__ import annotations

import math
import os
import tempfile
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from g1_control.errors import LaunchFileError
from g1_control.interfaces import InputDevice
from g1_control.teleop import evdev_protocol as ev
from g1_control.teleop.gamepad import HAT_BUTTONS, XPAD_AXIS_CODES, XPAD_AXIS_RANGES, XPAD_BUTTON_CODES
from g1_control.teleop.layouts import GAMEPAD_AXES, GAMEPAD_BUTTONS, STICK

# d-pad buttons go out as the hat axis xpad uses: name -> (hat code, value when pressed)
_HAT_OF = {name: (code, -1 if i == 0 else 1) for code, pair in HAT_BUTTONS.items() for i, name in enumerate(pair)}


@dataclass(frozen=True)
class GamepadStep:
    t_s: float
    axes: dict[str, float]
    press: tuple[str, ...] = ()
    release: tuple[str, ...] = ()


def _raw(axis: str, value: float) -> int:
    lo, hi = XPAD_AXIS_RANGES[axis]
    if GAMEPAD_AXES[axis] == STICK:
        return round(((value + 1.0) * (hi - lo)) / 2.0 + lo)
    return round(lo + value * (hi - lo))


def step_events(step: GamepadStep) -> bytes:
    """One SYN_REPORT frame with every change of the step."""
    out = []
    for axis, value in step.axes.items():
        out.append(ev.pack_event(ev.EV_ABS, XPAD_AXIS_CODES[axis], _raw(axis, value), step.t_s))
    for names, value in ((step.press, 1), (step.release, 0)):
        for name in names:
            if name in _HAT_OF:
                code, direction = _HAT_OF[name]
                out.append(ev.pack_event(ev.EV_ABS, code, direction * value, step.t_s))
            else:
                out.append(ev.pack_event(ev.EV_KEY, XPAD_BUTTON_CODES[name], value, step.t_s))
    out.append(ev.syn_report(step.t_s))
    return b"".join(out)


def parse_gamepad_script(steps: Any, where: str) -> list[GamepadStep]:
    """Validate a script (list of {t_s, axes, press, release}); LaunchFileError names the step."""
    if not isinstance(steps, Sequence) or isinstance(steps, (str, bytes)) or not steps:
        raise LaunchFileError(f"{where} is {type(steps).__name__}; expected a non-empty list of steps")
    out: list[GamepadStep] = []
    last_t = -math.inf
    for i, step in enumerate(steps):
        here = f"{where}[{i}]"
        if not isinstance(step, Mapping):
            raise LaunchFileError(f"{here} is {type(step).__name__}; expected a mapping with t_s")
        for key in step:
            if key not in ("t_s", "axes", "press", "release"):
                raise LaunchFileError(f"{here}.{key} is not a step field; known: t_s, axes, press, release")
        t_s = step.get("t_s")
        if isinstance(t_s, bool) or not isinstance(t_s, (int, float)) or not math.isfinite(t_s) or t_s < 0:
            raise LaunchFileError(f"{here}.t_s is {t_s!r}; expected a time in seconds >= 0")
        if t_s < last_t:
            raise LaunchFileError(f"{here}.t_s is {t_s}, before the previous step's {last_t}; steps must be in time order")
        last_t = t_s
        axes = step.get("axes", {})
        if not isinstance(axes, Mapping):
            raise LaunchFileError(f"{here}.axes is {type(axes).__name__}; expected a mapping of axis -> value")
        for axis, value in axes.items():
            if axis not in GAMEPAD_AXES:
                raise LaunchFileError(f"{here}.axes.{axis} is not a gamepad axis; known: {', '.join(sorted(GAMEPAD_AXES))}")
            low = -1.0 if GAMEPAD_AXES[axis] == STICK else 0.0
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not low <= value <= 1.0:
                raise LaunchFileError(f"{here}.axes.{axis} is {value!r}; expected a number in [{low:g}, 1]")
        buttons = {}
        for key in ("press", "release"):
            names = step.get(key, [])
            if isinstance(names, str):
                names = [names]
            if not isinstance(names, Sequence) or not all(isinstance(n, str) for n in names):
                raise LaunchFileError(f"{here}.{key} is {names!r}; expected a list of button names")
            for name in names:
                if name not in GAMEPAD_BUTTONS:
                    raise LaunchFileError(f"{here}.{key}: '{name}' is not a gamepad button; "
                                          f"known: {', '.join(sorted(GAMEPAD_BUTTONS))}")
            buttons[key] = tuple(names)
        both = set(buttons["press"]) & set(buttons["release"])
        if both:
            raise LaunchFileError(f"{here}: {sorted(both)} both pressed and released in one step; use two steps")
        out.append(GamepadStep(float(t_s), {k: float(v) for k, v in axes.items()}, buttons["press"], buttons["release"]))
    return out


class GamepadScriptFeeder:
    """Owns a FIFO and writes each step's frame into it once `advance(t_s)` reaches the step."""

    def __init__(self, steps: list[GamepadStep]) -> None:
        self._steps = steps
        self._next = 0
        self._dir = tempfile.TemporaryDirectory(prefix="g1_gamepad_script_")
        self.path = os.path.join(self._dir.name, "event-script")
        os.mkfifo(self.path)
        # Opened read-write so that the writer side exists before any reader opens the path:
        # a reader that finds no writer would see end-of-stream and report the pad lost.
        self._fd = os.open(self.path, os.O_RDWR | os.O_NONBLOCK | os.O_CLOEXEC)

    @property
    def done(self) -> bool:
        return self._next >= len(self._steps)

    def advance(self, t_s: float) -> int:
        """Write every step due by `t_s`; returns how many were written."""
        written = 0
        while self._next < len(self._steps) and self._steps[self._next].t_s <= t_s:
            os.write(self._fd, step_events(self._steps[self._next]))
            self._next += 1
            written += 1
        return written

    def unplug(self) -> None:
        """End the stream: the gamepad reading it sees what an unplugged pad does and is lost.
        (Its own read end is closed too, so the reader holds the only one and gets EOF.)"""
        if self._fd >= 0:
            os.close(self._fd)
            self._fd = -1

    def close(self) -> None:
        self.unplug()
        self._dir.cleanup()

    def __enter__(self):
        return self

    def __exit__(self, *exc) -> None:
        self.close()


class ScriptedGamepad(InputDevice):
    """A gamepad script played through the real evdev reader: an InputDevice whose poll() first
    writes the steps due by `clock()` into the FIFO, then reads them back as a pad would."""

    def __init__(self, steps: list[GamepadStep], make_gamepad, clock=None) -> None:
        self.feeder = GamepadScriptFeeder(steps)
        self.gamepad = make_gamepad(self.feeder.path)
        self.clock = clock or time.monotonic

    @property
    def lost(self) -> bool:
        return self.gamepad.lost

    def poll(self, now_s: float | None = None):
        now = self.clock() if now_s is None else now_s
        self.feeder.advance(now)
        return self.gamepad.poll(now)

    def close(self) -> None:
        self.gamepad.close()
        self.feeder.close()
