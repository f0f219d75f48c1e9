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
    if cfg.type == "program":
        return make_program_input(launch)
    if cfg.type == "ros2":
        from g1_control.teleop.ros2 import Ros2Bridge, ros2_settings

        return Ros2Bridge(**ros2_settings(cfg.device), limits=limits)
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
        return _instructed(launch, make_input_device(device_cfg, "input.device", limits=limits,
                                                     state_source=state_source))
    except InputDeviceError:
        if cfg.type == "gamepad" and cfg.fallback == "keyboard":
            keyboard_cfg = {"type": "keyboard"}
            print("input: no gamepad found; using the keyboard (see g1_control/teleop/README.md for keys)")
            return _instructed(launch, make_input_device(keyboard_cfg, "input.device", limits=limits))
        raise


def _instructed(launch: LaunchFile, device: InputDevice) -> InputDevice:
    """A keyboard takes typed instructions ('/' then a line; g1_control/program/instructed.py); on a
    robot each program is shown and runs only once the operator confirms it."""
    from g1_control.teleop.keyboard import TerminalKeyboard

    if not isinstance(device, TerminalKeyboard):
        return device
    from g1_control.program.instructed import InstructedInput

    return InstructedInput(device, program_world(launch), pose=launch.input.pose,
                           confirm=launch.backend.type != "mujoco")


def program_world(launch: LaunchFile):
    """The named places a program in `launch` may refer to: the scene's tables, platforms and boxes
    and input.places."""
    return launch.program_world()


def make_program_input(launch: LaunchFile, program=None, **kwargs):
    """A ProgramInput for `program` (default: the launch file's input.program / instruction) against
    the launch file's places; steering by input.pose. The loop feeds it back before every poll (InputDevice.observe)."""
    from g1_control.program.device import ProgramInput

    cfg = launch.input
    return ProgramInput(program if program is not None else cfg.parsed_program(), program_world(launch),
                        pose=cfg.pose, start_delay_s=cfg.start_delay_s, **kwargs)


PROGRAM_LAUNCH = "sim_program"
SCENE_PROGRAM_LAUNCH = "sim_scene_program"


def program_launch_name(program) -> str:
    """The shipped launch file for running `program`: sim_scene_program (tables, a box, a platform,
    a door; the execution layer) when it names a place other than the start or has a goal step
    (reach, pick, place, step up/down), else sim_program."""
    from g1_control.program.steps import GOAL_STEPS, iter_named_places, iter_steps

    named = {name for step in program.steps for _, name in iter_named_places(step)}
    goals = any(isinstance(s, GOAL_STEPS) for step in program.steps for s in iter_steps(step))
    return SCENE_PROGRAM_LAUNCH if goals or named - {"start"} else PROGRAM_LAUNCH
