"""Building devices from launch-file sections: validation at launch, each device type."""

import os
import select

import pytest

from g1_control.errors import InputDeviceError, LaunchFileError
from g1_control.teleop import evdev_protocol as ev
from g1_control.teleop.factory import make_input_device
from g1_control.teleop.gamepad import EvdevGamepad
from g1_control.teleop.keyboard import TerminalKeyboard
from g1_control.teleop.unitree_remote import UnitreeRemote, encode_wireless_remote
from g1_control.types import CommandLimits, RobotState


@pytest.mark.parametrize(
    "config, error, message",
    [
        ({"type": "joystick"}, LaunchFileError, "input.type is 'joystick'; expected one of gamepad, unitree_remote, keyboard"),
        ({"type": "gamepad"}, LaunchFileError, "input.path is None; a gamepad needs the path of its evdev node"),
        ({"type": "gamepad", "path": "/dev/input/event42"}, InputDeviceError,
         "input.path: gamepad device '/dev/input/event42' does not exist"),
        ({"type": "gamepad", "path": "/dev/null", "mapping": {"buttons": {"A": "run", "Start": "start"}}},
         LaunchFileError, "input.mapping.buttons.Start: 'Start' is not a button of a gamepad"),
        ({"type": "gamepad", "path": "/dev/null", "button_codes": [1]}, LaunchFileError,
         "input.button_codes is list; expected a mapping"),
        ({"type": "keyboard", "stale_after_s": 1}, LaunchFileError, "input.stale_after_s is not a setting of a keyboard"),
        ({"type": "keyboard", "path": "/dev/pts/999999"}, InputDeviceError, "terminal '/dev/pts/999999' does not exist"),
        ({"type": "unitree_remote", "stale_after_s": 0}, LaunchFileError, "input.stale_after_s is 0; expected a positive"),
        ({"type": "unitree_remote"}, LaunchFileError, "no state source was given"),
        ({"type": "unitree_remote", "path": "/dev/x"}, LaunchFileError, "input.path is not a setting of a unitree_remote"),
        ("gamepad", LaunchFileError, "input is str; expected a mapping with a 'type'"),
    ],
)
def test_bad_config_fails_at_launch(config, error, message):
    with pytest.raises(error) as err:
        make_input_device(config, "input", state_source=None)
    assert message in str(err.value)


def test_gamepad_from_config(tmp_path):
    path = tmp_path / "event0"
    os.mkfifo(path)
    device = make_input_device(
        {"type": "gamepad", "path": str(path),
         "mapping": {"buttons": {"Y": "estop"}, "slew_rate": {"vx": None}, "axes": {"speed_scale": None}}},
        limits=CommandLimits(vx_mps=(-0.2, 0.4)))
    assert isinstance(device, EvdevGamepad)
    w = os.open(path, os.O_WRONLY)
    os.write(w, ev.pack_event(ev.EV_ABS, ev.ABS_Y, -32768) + ev.pack_event(ev.EV_KEY, ev.BTN_WEST, 1) + ev.syn_report())
    cmd = device.poll()
    assert cmd.buttons == {"estop"} and cmd.vx_mps == 0.0
    os.write(w, ev.pack_event(ev.EV_ABS, ev.ABS_Y, -32000) + ev.syn_report())
    # default vx shaping: inverted Y, 0.1 deadzone rescaled, expo 0.3, then the 0.4 m/s limit
    x = 63999 / 65535
    m = (x - 0.1) / 0.9
    assert device.poll().vx_mps == pytest.approx(0.4 * (0.7 * m + 0.3 * m**3))
    os.close(w)
    device.close()


def test_gamepad_auto_without_gamepads(monkeypatch):
    monkeypatch.setattr("g1_control.teleop.gamepad.find_gamepads", list)
    with pytest.raises(InputDeviceError, match="input.path is 'auto' but no gamepad was found"):
        make_input_device({"type": "gamepad", "path": "auto"})


def test_remote_from_config_reads_robot_state():
    state = RobotState(tick=1, wireless_remote=encode_wireless_remote({"start"}, ly=1.0))
    device = make_input_device({"type": "unitree_remote", "stale_after_s": 0.5,
                                "mapping": {"slew_rate": {"vx": None}}}, state_source=lambda: state)
    assert isinstance(device, UnitreeRemote) and device.stale_after_s == 0.5
    cmd = device.poll()
    assert cmd.buttons == {"start"} and cmd.vx_mps == pytest.approx(1.0)


def test_keyboard_from_config_on_a_pty():
    master, slave = os.openpty()
    try:
        device = make_input_device({"type": "keyboard", "path": os.ttyname(slave), "mapping": {"buttons": {"p": "estop"}}})
        assert isinstance(device, TerminalKeyboard)
        os.write(master, b"p")
        assert select.select([device.fileno()], [], [], 5.0)[0]
        assert device.poll().buttons == {"estop"}
        device.close()
    finally:
        os.close(master)
        os.close(slave)
