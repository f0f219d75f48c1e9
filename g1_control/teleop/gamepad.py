"""A USB gamepad read straight from its Linux evdev node (/dev/input/eventN).

Events are applied in frames: the kernel groups the changes of one moment and ends them with
SYN_REPORT, and a reader that overflowed the kernel's buffer gets SYN_DROPPED, after which it
must discard up to the next SYN_REPORT and query the true state (EVIOCGKEY / EVIOCGABS). On a
pipe or a recorded file (tests, replays) those ioctls do not exist, so after a drop every button
reads released and every axis at rest: the safe guess.

The file descriptor is non-blocking and read inside poll(): no thread, and an event written
before poll() is in that poll's Command.
"""

from __future__ import annotations

import errno
import glob
import os
import stat
import struct
import time
from collections.abc import Callable, Mapping
from typing import Any

from g1_control.errors import InputDeviceError, LaunchFileError
from g1_control.teleop import evdev_protocol as ev
from g1_control.teleop.device import DeviceLost, TeleopDevice
from g1_control.teleop.layouts import GAMEPAD_AXES, GAMEPAD_BUTTONS, STICK
from g1_control.teleop.mapping import MappingConfig
from g1_control.teleop.snapshot import InputSnapshot
from g1_control.types import CommandLimits

# Codes the Linux xpad driver (Xbox 360 / One pads) reports; other pads differ and are set in
# the launch file with `button_codes` / `axis_codes`. xpad reports the Xbox "X" as BTN_X (0x133,
# which the header also calls BTN_NORTH) and "Y" as BTN_Y (0x134, BTN_WEST).
XPAD_BUTTON_CODES = {
    "A": ev.BTN_SOUTH, "B": ev.BTN_EAST, "X": ev.BTN_NORTH, "Y": ev.BTN_WEST,
    "LB": ev.BTN_TL, "RB": ev.BTN_TR, "back": ev.BTN_SELECT, "start": ev.BTN_START,
    "guide": ev.BTN_MODE, "LS": ev.BTN_THUMBL, "RS": ev.BTN_THUMBR,
    "dpad_up": ev.BTN_DPAD_UP, "dpad_down": ev.BTN_DPAD_DOWN,
    "dpad_left": ev.BTN_DPAD_LEFT, "dpad_right": ev.BTN_DPAD_RIGHT,
}
XPAD_AXIS_CODES = {
    "left_x": ev.ABS_X, "left_y": ev.ABS_Y, "right_x": ev.ABS_RX, "right_y": ev.ABS_RY,
    "left_trigger": ev.ABS_Z, "right_trigger": ev.ABS_RZ,
}
# Used only where the device cannot be asked (EVIOCGABS fails on pipes and files): xpad's
# stick range, and its Xbox One trigger range (the 360 reports 0..255; a real node is asked).
XPAD_AXIS_RANGES = {
    "left_x": (-32768, 32767), "left_y": (-32768, 32767),
    "right_x": (-32768, 32767), "right_y": (-32768, 32767),
    "left_trigger": (0, 1023), "right_trigger": (0, 1023),
}
# The d-pad arrives as a hat axis on xpad: (negative, positive) direction buttons.
HAT_BUTTONS = {ev.ABS_HAT0X: ("dpad_left", "dpad_right"), ev.ABS_HAT0Y: ("dpad_up", "dpad_down")}

_READ_CHUNK = ev.EVENT_SIZE * 64


def _codes(spec: Mapping[str, Any] | None, defaults: dict[str, int], names: frozenset[str] | dict,
           where: str) -> dict[str, int]:
    out = dict(defaults)
    for name, code in (spec or {}).items():
        if name not in names:
            raise LaunchFileError(f"{where}.{name} is not a gamepad name; known: {', '.join(sorted(names))}")
        if isinstance(code, bool) or not isinstance(code, int) or not 0 <= code < 0x300:
            raise LaunchFileError(f"{where}.{name} is {code!r}; expected an evdev code (integer 0..767)")
        out[name] = code
    codes = sorted(out.values())
    if len(set(codes)) != len(codes):
        raise LaunchFileError(f"{where}: two names share one evdev code: {out}")
    return out


def _ranges(spec: Mapping[str, Any] | None, where: str) -> dict[str, tuple[int, int]]:
    out = {}
    for name, value in (spec or {}).items():
        if name not in GAMEPAD_AXES:
            raise LaunchFileError(f"{where}.{name} is not a gamepad axis; known: {', '.join(sorted(GAMEPAD_AXES))}")
        if (not isinstance(value, (list, tuple)) or len(value) != 2
                or not all(isinstance(v, int) and not isinstance(v, bool) for v in value) or value[0] >= value[1]):
            raise LaunchFileError(f"{where}.{name} is {value!r}; expected [minimum, maximum], integers, minimum < maximum")
        out[name] = (value[0], value[1])
    return out


def find_gamepads(input_dir: str = "/dev/input") -> list[str]:
    """evdev nodes under `input_dir` that have face buttons and a left stick, sorted by path."""
    found = []
    for path in sorted(glob.glob(os.path.join(input_dir, "event*"))):
        try:
            fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | os.O_CLOEXEC)
        except OSError:
            continue
        try:
            keys = ev.ioctl_buffer(fd, ev.EVIOCGBIT(ev.EV_KEY, ev.KEY_CNT // 8), ev.KEY_CNT // 8)
            axes = ev.ioctl_buffer(fd, ev.EVIOCGBIT(ev.EV_ABS, ev.ABS_CNT // 8), ev.ABS_CNT // 8)
        except OSError:
            continue
        finally:
            os.close(fd)
        if ev.bit_set(keys, ev.BTN_SOUTH) and ev.bit_set(axes, ev.ABS_X) and ev.bit_set(axes, ev.ABS_Y):
            found.append(path)
    return found


def _open_hint() -> str:
    joysticks = sorted(glob.glob("/dev/input/by-id/*-event-joystick"))
    if joysticks:
        return "gamepads present: " + ", ".join(joysticks)
    return "no /dev/input/by-id/*-event-joystick is present: is the gamepad plugged in (and /dev/input mounted)?"


class EvdevGamepad(TeleopDevice):
    """A gamepad on a Linux evdev node, a pipe or a recorded event file."""

    kind = "gamepad"

    def __init__(self, path: str, mapping: MappingConfig | None = None, limits: CommandLimits | None = None, *,
                 button_codes: Mapping[str, Any] | None = None, axis_codes: Mapping[str, Any] | None = None,
                 axis_ranges: Mapping[str, Any] | None = None, where: str = "input",
                 clock: Callable[[], float] = time.monotonic, name: str | None = None) -> None:
        super().__init__(mapping or MappingConfig.default("gamepad"), limits, name=name or f"gamepad {path}", clock=clock)
        self.path = path
        self._button_by_code = {code: n for n, code in
                                _codes(button_codes, XPAD_BUTTON_CODES, GAMEPAD_BUTTONS, f"{where}.button_codes").items()}
        self._axis_by_code = {code: n for n, code in
                              _codes(axis_codes, XPAD_AXIS_CODES, GAMEPAD_AXES, f"{where}.axis_codes").items()}
        overrides = _ranges(axis_ranges, f"{where}.axis_ranges")
        self._fd = self._open(path, where)
        mode = os.fstat(self._fd).st_mode
        self._is_evdev = stat.S_ISCHR(mode)
        # A recorded file ends without the device going away; a pipe or a node that ends is gone.
        self._eof_is_loss = not stat.S_ISREG(mode)
        self._ranges: dict[str, tuple[int, int]] = {}
        for code, axis in self._axis_by_code.items():
            rng = overrides.get(axis)
            if rng is None and self._is_evdev:
                try:
                    _, lo, hi = ev.absinfo(self._fd, code)
                    rng = (lo, hi) if hi > lo else None
                except OSError:
                    rng = None  # the pad has no such axis; keep the default so names still resolve
            self._ranges[axis] = rng or overrides.get(axis) or XPAD_AXIS_RANGES[axis]
        self._axes = {axis: 0.0 for axis in GAMEPAD_AXES}
        self._held: set[str] = set()
        self._pending_axes: dict[str, float] = {}
        self._pending_keys: dict[str, bool] = {}
        self._pending_presses: list[str] = []
        self._presses: list[str] = []
        self._dropping = False
        self._buffer = bytearray()
        self.dropped_frames = 0
        self.events_read = 0
        self._read_bytes = os.read  # the one call that touches the device
        if self._is_evdev:
            self._resync()

    def _open(self, path: str, where: str) -> int:
        try:
            fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | os.O_CLOEXEC)
        except FileNotFoundError:
            raise InputDeviceError(f"{where}.path: gamepad device {path!r} does not exist; {_open_hint()}") from None
        except PermissionError:
            raise InputDeviceError(
                f"{where}.path: no permission to read {path!r}; add the user to the 'input' group "
                "(or a udev rule granting read access) and log in again") from None
        except OSError as exc:
            raise InputDeviceError(f"{where}.path: cannot open gamepad device {path!r}: {exc.strerror}") from None
        mode = os.fstat(fd).st_mode
        if not (stat.S_ISCHR(mode) or stat.S_ISFIFO(mode) or stat.S_ISREG(mode)):
            os.close(fd)
            raise InputDeviceError(f"{where}.path: {path!r} is not a device, pipe or event file")
        if stat.S_ISCHR(mode):
            try:
                ev.ioctl_buffer(fd, ev.EVIOCGVERSION, 4)
            except OSError:
                os.close(fd)
                raise InputDeviceError(
                    f"{where}.path: {path!r} is not an evdev device (the old joystick API /dev/input/jsN "
                    "and serial ports are not); use the gamepad's /dev/input/eventN or "
                    "/dev/input/by-id/*-event-joystick") from None
        return fd

    def fileno(self) -> int:
        """For select()/poll() by a caller that wants to wait for input."""
        return self._fd

    def _release(self) -> None:
        if self._fd >= 0:
            os.close(self._fd)
            self._fd = -1

    # -- reading ----------------------------------------------------------------------------
    def _read(self) -> InputSnapshot:
        while True:
            try:
                chunk = self._read_bytes(self._fd, _READ_CHUNK)
            except BlockingIOError:
                break
            except InterruptedError:
                continue
            except OSError as exc:
                name = errno.errorcode.get(exc.errno or 0, str(exc.errno))
                raise DeviceLost(f"{self.path}: read failed with {name} ({exc.strerror}): unplugged?") from None
            if not chunk:
                if self._eof_is_loss:
                    raise DeviceLost(f"{self.path}: end of stream (device closed)")
                break
            self._buffer += chunk
            whole = len(self._buffer) - len(self._buffer) % ev.EVENT_SIZE
            for _, _, ev_type, code, value in struct.iter_unpack(ev.EVENT_FORMAT, self._buffer[:whole]):
                self._event(ev_type, code, value)
            del self._buffer[:whole]
        presses, self._presses = tuple(self._presses), []
        return InputSnapshot(axes=dict(self._axes), held=frozenset(self._held), pressed=presses)

    def _event(self, ev_type: int, code: int, value: int) -> None:
        self.events_read += 1
        if ev_type == ev.EV_SYN:
            if code == ev.SYN_REPORT:
                if self._dropping:
                    self._dropping = False
                    self._resync()
                else:
                    self._axes.update(self._pending_axes)
                    for button, down in self._pending_keys.items():
                        (self._held.add if down else self._held.discard)(button)
                    self._presses.extend(self._pending_presses)
                self._clear_pending()
            elif code == ev.SYN_DROPPED:
                self.dropped_frames += 1
                self._dropping = True
                self._clear_pending()
        elif self._dropping:
            return
        elif ev_type == ev.EV_KEY:
            mapped = self._button_by_code.get(code)
            if mapped is not None and value != ev.KEY_REPEAT:
                self._pending_keys[mapped] = value == ev.KEY_PRESS
                if value == ev.KEY_PRESS:
                    self._pending_presses.append(mapped)
        elif ev_type == ev.EV_ABS:
            if code in HAT_BUTTONS:
                negative, positive = HAT_BUTTONS[code]
                for button, down in ((negative, value < 0), (positive, value > 0)):
                    if down and not self._pending_keys.get(button, button in self._held):
                        self._pending_presses.append(button)
                    self._pending_keys[button] = down
                return
            axis = self._axis_by_code.get(code)
            if axis is not None:
                self._pending_axes[axis] = self._normalize(axis, value)

    def _normalize(self, axis: str, value: int) -> float:
        lo, hi = self._ranges[axis]
        if GAMEPAD_AXES[axis] == STICK:
            return (2.0 * value - (lo + hi)) / (hi - lo)
        return (value - lo) / (hi - lo)

    def _clear_pending(self) -> None:
        self._pending_axes.clear()
        self._pending_keys.clear()
        self._pending_presses.clear()

    def _resync(self) -> None:
        """Take the device's true state after a drop (and at start); at rest where unknowable."""
        try:
            keys = ev.ioctl_buffer(self._fd, ev.EVIOCGKEY(ev.KEY_CNT // 8), ev.KEY_CNT // 8)
            held = {b for code, b in self._button_by_code.items() if ev.bit_set(keys, code)}
        except OSError:
            held = set()
        for code, axis in self._axis_by_code.items():
            try:
                self._axes[axis] = self._normalize(axis, ev.absinfo(self._fd, code)[0])
            except OSError:
                self._axes[axis] = 0.0
        for code, (negative, positive) in HAT_BUTTONS.items():
            try:
                value = ev.absinfo(self._fd, code)[0]
            except OSError:
                continue
            if value:
                held.add(negative if value < 0 else positive)
        self._held = held
