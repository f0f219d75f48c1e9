"""Build an input device from its launch-file section.

    input:
      type: gamepad            # gamepad | unitree_remote | keyboard
      path: /dev/input/by-id/usb-Microsoft_Controller-event-joystick   # or "auto"
      mapping: {...}           # see mapping.py; absent = the device's default
      # gamepad only:  button_codes, axis_codes, axis_ranges (for pads that are not xpad)
      # keyboard only: path of a tty (default: this process's stdin)
      # unitree_remote only: stale_after_s (default 0.25)

Everything is validated (LaunchFileError naming the key path) and the device opened here, so a
missing gamepad is an error at launch, not a surprise once the robot stands.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Mapping
from typing import Any

from g1_control.errors import InputDeviceError, LaunchFileError
from g1_control.teleop.device import TeleopDevice
from g1_control.teleop.layouts import LAYOUTS
from g1_control.teleop.mapping import MappingConfig
from g1_control.types import CommandLimits, RobotState

DEVICE_TYPES = tuple(LAYOUTS)
_KEYS = {
    "gamepad": ("type", "path", "mapping", "button_codes", "axis_codes", "axis_ranges"),
    "unitree_remote": ("type", "mapping", "stale_after_s"),
    "keyboard": ("type", "path", "mapping"),
}


def make_input_device(config: Mapping[str, Any], where: str = "input", *, limits: CommandLimits | None = None,
                      state_source: Callable[[], RobotState | bytes | None] | None = None,
                      clock: Callable[[], float] = time.monotonic) -> TeleopDevice:
    """The device `config` describes, open and ready to poll.

    limits: the tracker's command limits (CommandLimits.from_tracker_metadata).
    state_source: for unitree_remote, returns the latest RobotState (the backend's read_state).
    """
    if not isinstance(config, Mapping):
        raise LaunchFileError(f"{where} is {type(config).__name__}; expected a mapping with a 'type'")
    kind = config.get("type")
    if kind not in LAYOUTS:
        raise LaunchFileError(f"{where}.type is {kind!r}; expected one of {', '.join(DEVICE_TYPES)}")
    for key in config:
        if key not in _KEYS[kind]:
            raise LaunchFileError(f"{where}.{key} is not a setting of a {kind}; known: {', '.join(_KEYS[kind])}")
    mapping = MappingConfig.from_dict(config.get("mapping"), f"{where}.mapping", layout=LAYOUTS[kind])

    if kind == "gamepad":
        from g1_control.teleop.gamepad import EvdevGamepad, find_gamepads

        path = config.get("path")
        if not isinstance(path, str) or not path:
            raise LaunchFileError(f"{where}.path is {path!r}; a gamepad needs the path of its evdev node, or 'auto'")
        if path == "auto":
            found = find_gamepads()
            if not found:
                raise InputDeviceError(f"{where}.path is 'auto' but no gamepad was found under /dev/input "
                                       "(plugged in? readable by this user: 'input' group?)")
            path = found[0]
        for key in ("button_codes", "axis_codes", "axis_ranges"):
            if key in config and not isinstance(config[key], Mapping):
                raise LaunchFileError(f"{where}.{key} is {type(config[key]).__name__}; expected a mapping")
        return EvdevGamepad(path, mapping, limits, button_codes=config.get("button_codes"),
                            axis_codes=config.get("axis_codes"), axis_ranges=config.get("axis_ranges"),
                            where=where, clock=clock)
    if kind == "keyboard":
        from g1_control.teleop.keyboard import TerminalKeyboard

        path = config.get("path")
        if path is not None and (not isinstance(path, str) or not path):
            raise LaunchFileError(f"{where}.path is {path!r}; expected the path of a terminal, or leave it out")
        return TerminalKeyboard(mapping, limits, path=path, where=where, clock=clock)

    from g1_control.teleop.unitree_remote import UnitreeRemote

    stale = config.get("stale_after_s", 0.25)
    if isinstance(stale, bool) or not isinstance(stale, (int, float)) or not 0 < stale < float("inf"):
        raise LaunchFileError(f"{where}.stale_after_s is {stale!r}; expected a positive number of seconds")
    if state_source is None:
        raise LaunchFileError(f"{where}: a unitree_remote reads the robot's state, but no state source was given "
                              "(it works only with a backend that reports wireless_remote bytes)")
    return UnitreeRemote(mapping, limits, state_source=state_source, stale_after_s=stale, clock=clock)
