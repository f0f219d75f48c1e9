"""Operator input: gamepad (evdev), Unitree remote (lowstate bytes), terminal keyboard.

Each device is an InputDevice whose poll() returns a Command, mapped through a per-device
MappingConfig validated from the launch file (make_input_device builds one from its section).
See README.md here for the default button mappings.
"""

from g1_control.teleop.factory import make_input_device
from g1_control.teleop.mapping import MappingConfig
from g1_control.types import CommandLimits

__all__ = ["CommandLimits", "MappingConfig", "make_input_device"]
