"""The names each kind of input device reports, and its default mapping.

A layout is what a mapping is validated against: which button and axis names exist, whether
chords ("L1+R1") are possible, and how each axis rests (sticks centre at 0 in [-1, 1], triggers
rest at 0 in [0, 1]). Default mappings follow the conventions operators of the G1 already know:

- Unitree's own G1 deployment example (unitree_rl_gym deploy/deploy_real): `start` moves the
  robot to its default pose, `A` starts the policy, `select` drops it into damping; left stick
  forward/back -> vx, left stick left/right -> vy, right stick left/right -> yaw rate.
- Amazon FAR's holosoma-inference 0.1.3 (inputs/impl/joystick.py, interface.py): `A` start,
  `B` stop, `L1+R1` kill, `X` switch mode; vx = ly, vy = -lx, wz = -rx with a 0.1 deadzone.

Goal buttons (issue 17; executed by tracker.type layer against the launch file's scene): `Y` picks
the box in front, `LB+Y` / `L1+Y` sets it down in front, d-pad up steps onto the platform in front,
d-pad down steps back off it (keyboard: p, l, u, n).
"""

from __future__ import annotations

import string
from dataclasses import dataclass, field
from typing import Any

from g1_control.hardware.unitree.remote import REMOTE_BUTTON_BITS

STICK = "stick"
TRIGGER = "trigger"


@dataclass(frozen=True)
class DeviceLayout:
    kind: str
    axes: dict[str, str]
    """Axis name -> STICK (rests at 0, range [-1, 1]) or TRIGGER (rests at 0, range [0, 1])."""
    buttons: frozenset[str]
    chords: bool
    """Whether "A+B" names a chord (devices that report releases); a terminal keyboard cannot."""
    default_mapping: dict[str, Any] = field(default_factory=dict)
    key_axes: bool = False
    """Axes are virtual, moved by key presses (`key_axes` section of the mapping)."""


# --- USB gamepad (Xbox layout as the Linux xpad driver reports it) -----------------------------
GAMEPAD_BUTTONS = frozenset(
    {"A", "B", "X", "Y", "LB", "RB", "back", "start", "guide", "LS", "RS",
     "dpad_up", "dpad_down", "dpad_left", "dpad_right"}
)
GAMEPAD_AXES = {
    "left_x": STICK, "left_y": STICK, "right_x": STICK, "right_y": STICK,
    "left_trigger": TRIGGER, "right_trigger": TRIGGER,
}
# Linux reports stick Y positive when pushed DOWN and X positive to the right; the robot's vx is
# forward and vy, wz are positive to the left (counter-clockwise), hence all three inverted.
GAMEPAD_DEFAULT_MAPPING: dict[str, Any] = {
    "axes": {
        "vx": {"axis": "left_y", "invert": True, "deadzone": 0.1, "expo": 0.3},
        "vy": {"axis": "left_x", "invert": True, "deadzone": 0.1, "expo": 0.3},
        "wz": {"axis": "right_x", "invert": True, "deadzone": 0.1, "expo": 0.3},
        "speed_scale": {"axis": "right_trigger", "deadzone": 0.05},
        "pelvis_height": {"axis": "left_trigger", "deadzone": 0.05},
    },
    "buttons": {
        "start": "start", "A": "run", "B": "stop", "back": "damp", "LB+RB": "estop",
        "X": "policy_switch", "dpad_right": "style_next", "dpad_left": "style_prev",
        "Y": "pick", "LB+Y": "place", "dpad_up": "step_up", "dpad_down": "step_down",
    },
    "slew_rate": {"vx": 1.0, "vy": 1.0, "wz": 2.0},
    "speed_scale_range": [0.5, 1.0],
}

# --- Unitree handheld remote (bytes in LowState.wireless_remote) -------------------------------
REMOTE_BUTTONS = frozenset(REMOTE_BUTTON_BITS)
REMOTE_AXES = {"lx": STICK, "ly": STICK, "rx": STICK, "ry": STICK, "L2": TRIGGER}
# The remote reports ly positive forward (unlike evdev), so only vy and wz flip sign.
REMOTE_DEFAULT_MAPPING: dict[str, Any] = {
    "axes": {
        "vx": {"axis": "ly", "deadzone": 0.1, "expo": 0.3},
        "vy": {"axis": "lx", "invert": True, "deadzone": 0.1, "expo": 0.3},
        "wz": {"axis": "rx", "invert": True, "deadzone": 0.1, "expo": 0.3},
    },
    # L2+R2 and L2+B are left free: the robot's own firmware uses them (debug mode, damping)
    # and an operator's muscle memory for them must not trigger something else here.
    "buttons": {
        "start": "start", "A": "run", "B": "stop", "select": "damp", "L1+R1": "estop",
        "X": "policy_switch", "right": "style_next", "left": "style_prev",
        "Y": "pick", "L1+Y": "place", "up": "step_up", "down": "step_down",
    },
    "slew_rate": {"vx": 1.0, "vy": 1.0, "wz": 2.0},
}

# --- Terminal keyboard ------------------------------------------------------------------------
NAMED_KEYS = frozenset(
    {"up", "down", "left", "right", "esc", "enter", "space", "tab", "backspace",
     "home", "end", "insert", "delete", "page_up", "page_down"}
    | {f"ctrl+{c}" for c in string.ascii_lowercase if c not in "cijmz"}
)
"""Keys with names; ctrl+c/ctrl+z stay with the terminal (interrupt, suspend) and ctrl+i/j/m
are the same bytes as tab and enter."""
# Letters are reported lower-case (caps lock must not disable the stop keys).
PRINTABLE_KEYS = frozenset(c for c in string.printable if c not in string.whitespace and not c.isupper())
KEYBOARD_KEYS = NAMED_KEYS | PRINTABLE_KEYS
KEYBOARD_AXES = {"forward": STICK, "lateral": STICK, "yaw": STICK, "speed": TRIGGER, "crouch": TRIGGER}
# A terminal reports presses but never releases, so velocity keys step virtual axes (as
# holosoma's keyboard does) and `space` zeroes them; there is no "release to stop" here.
KEYBOARD_DEFAULT_MAPPING: dict[str, Any] = {
    "axes": {
        "vx": {"axis": "forward"},
        "vy": {"axis": "lateral"},
        "wz": {"axis": "yaw"},
        "pelvis_height": {"axis": "crouch"},
    },
    "key_axes": {
        "w": ["forward", 0.1], "s": ["forward", -0.1],
        "a": ["lateral", 0.1], "d": ["lateral", -0.1],
        "q": ["yaw", 0.1], "e": ["yaw", -0.1],
        "c": ["crouch", 0.25], "v": ["crouch", -0.25],
    },
    "buttons": {
        "enter": "start", "r": "run", "o": "stop", "x": "damp", "esc": "estop",
        "space": "zero_velocity", "tab": "policy_switch", "]": "style_next", "[": "style_prev",
        "p": "pick", "l": "place", "u": "step_up", "n": "step_down",
        "/": "instruction",
    },
    "slew_rate": {"vx": 1.0, "vy": 1.0, "wz": 2.0},
}

LAYOUTS: dict[str, DeviceLayout] = {
    "gamepad": DeviceLayout("gamepad", GAMEPAD_AXES, GAMEPAD_BUTTONS, True, GAMEPAD_DEFAULT_MAPPING),
    "unitree_remote": DeviceLayout("unitree_remote", REMOTE_AXES, REMOTE_BUTTONS, True, REMOTE_DEFAULT_MAPPING),
    "keyboard": DeviceLayout("keyboard", KEYBOARD_AXES, KEYBOARD_KEYS, False, KEYBOARD_DEFAULT_MAPPING,
                             key_axes=True),
}
