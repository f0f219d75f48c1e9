"""The launch file's command source as an InputDevice."""

from __future__ import annotations

from g1_control.errors import InputDeviceError
from g1_control.interfaces import InputDevice
from g1_control.launch.schema import TELEOP_DEVICES, LaunchFile
from g1_control.teleop.scripted import ScriptedInput, Segment
from g1_control.types import CommandLimits


def make_input(launch: LaunchFile, segments: list[Segment], limits: CommandLimits | None = None,
               state_source=None) -> InputDevice:
    """Open the device `launch.input` names. Teleop devices scale their sticks to `limits` (the
    loop builder's command limits); every device is timed by the loop's clock (poll(now_s)), so
    slew rates follow simulated time in lockstep."""
    cfg = launch.input
    if cfg.type in ("scripted", "random"):
        return ScriptedInput(segments)
    from g1_control.teleop.factory import make_input_device

    if cfg.type == "gamepad_script":
        from g1_control.teleop.gamepad_script import ScriptedGamepad, parse_gamepad_script

        steps = parse_gamepad_script(cfg.gamepad_script, "input.gamepad_script")

        def open_pad(path: str):
            return make_input_device(dict(cfg.device, type="gamepad", path=path), "input.device", limits=limits)

        return ScriptedGamepad(steps, open_pad)
    assert cfg.type in TELEOP_DEVICES
    device_cfg = dict(cfg.device, type=cfg.type)
    try:
        return make_input_device(device_cfg, "input.device", limits=limits, state_source=state_source)
    except InputDeviceError:
        if cfg.type == "gamepad" and cfg.fallback == "keyboard":
            keyboard_cfg = {"type": "keyboard"}
            print("input: no gamepad found; using the keyboard (see g1_control/teleop/README.md for keys)")
            return make_input_device(keyboard_cfg, "input.device", limits=limits)
        raise
