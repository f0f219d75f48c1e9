"""The terminal keyboard driven through a real pseudo-terminal (as over SSH)."""

import os
import select
import termios

import pytest

from g1_control.errors import InputDeviceError
from g1_control.teleop.keyboard import TerminalKeyboard, decode_keys
from g1_control.teleop.layouts import LAYOUTS
from g1_control.teleop.mapping import MappingConfig


class Clock:
    def __init__(self):
        self.t = 0.0

    def __call__(self):
        return self.t


@pytest.fixture
def pty_pair():
    master, slave = os.openpty()
    yield master, slave
    for fd in (master, slave):
        try:
            os.close(fd)
        except OSError:
            pass


def type_keys(master, keyboard, data: bytes):
    """Write as the terminal emulator would, and wait until the tty has passed it on."""
    os.write(master, data)
    assert select.select([keyboard.fileno()], [], [], 5.0)[0], "the pty never delivered the bytes"


def no_slew():
    return MappingConfig.from_dict({"slew_rate": {"vx": None, "vy": None, "wz": None}}, "m", layout=LAYOUTS["keyboard"])


def test_decode_keys():
    keys, unknown = decode_keys("wA \r\t\x1b[A\x1bOD\x1b[3~\x1b\x7f\x05é\x1b[99~]")
    assert keys == ["w", "a", "space", "enter", "tab", "up", "left", "delete", "esc", "backspace", "ctrl+e", "]"]
    assert unknown == 2


def test_raw_mode_is_set_and_restored(pty_pair):
    _, slave = pty_pair
    before = termios.tcgetattr(slave)
    keyboard = TerminalKeyboard(path=os.ttyname(slave), clock=Clock())
    now = termios.tcgetattr(slave)
    assert not now[3] & termios.ICANON and not now[3] & termios.ECHO
    assert now[3] & termios.ISIG  # Ctrl-C still interrupts the program
    assert not now[0] & termios.IXON
    keyboard.close()
    assert termios.tcgetattr(slave) == before


def test_keys_drive_the_command_over_a_pty(pty_pair):
    master, slave = pty_pair
    with TerminalKeyboard(no_slew(), path=os.ttyname(slave), clock=Clock()) as keyboard:
        assert keyboard.poll().vx_mps == 0.0  # nothing typed: nothing read, no blocking
        type_keys(master, keyboard, b"www")
        assert keyboard.poll().vx_mps == pytest.approx(0.3)
        type_keys(master, keyboard, b"aq")
        cmd = keyboard.poll()
        assert (cmd.vx_mps, cmd.vy_mps, cmd.wz_radps) == pytest.approx((0.3, 0.1, 0.1))
        assert keyboard.poll().vx_mps == pytest.approx(0.3)  # a terminal has no key release
        type_keys(master, keyboard, b" ")
        cmd = keyboard.poll()
        assert (cmd.vx_mps, cmd.vy_mps, cmd.wz_radps) == (0.0, 0.0, 0.0)
        type_keys(master, keyboard, b"\r")
        assert keyboard.poll().buttons == {"start"}
        type_keys(master, keyboard, b"R")  # caps lock / shift must not disable a key
        assert keyboard.poll().buttons == {"run"}
        type_keys(master, keyboard, b"]\t")
        assert keyboard.poll().buttons == {"style_next", "policy_switch"}


def test_escape_is_estop_and_arrows_are_not(pty_pair):
    master, slave = pty_pair
    clock = Clock()
    mapping = MappingConfig.from_dict({"slew_rate": {"vx": 0.5}}, "m", layout=LAYOUTS["keyboard"])
    with TerminalKeyboard(mapping, path=os.ttyname(slave), clock=clock) as keyboard:
        type_keys(master, keyboard, b"wwwww")
        for _ in range(20):
            clock.t += 0.1
            cmd = keyboard.poll()
        assert cmd.vx_mps == pytest.approx(0.5)
        type_keys(master, keyboard, b"\x1b[A\x1b[D")
        assert keyboard.poll().buttons == frozenset()
        type_keys(master, keyboard, b"\x1b")
        cmd = keyboard.poll()
        assert cmd.buttons == {"estop"} and cmd.vx_mps == 0.0


def test_terminal_hangup_is_loss(pty_pair, caplog):
    master, slave = pty_pair
    keyboard = TerminalKeyboard(no_slew(), path=os.ttyname(slave), clock=Clock())
    type_keys(master, keyboard, b"ww")
    assert keyboard.poll().vx_mps == pytest.approx(0.2)
    os.close(master)  # the SSH session goes away
    cmd = keyboard.poll()
    assert keyboard.lost and "terminal" in keyboard.lost_reason
    assert cmd.buttons == {"damp"} and cmd.vx_mps == 0.0 and "lost" in caplog.text
    keyboard.close()


def test_not_a_terminal_and_missing_path(tmp_path):
    read_end, write_end = os.pipe()
    try:
        with pytest.raises(InputDeviceError, match="keyboard input needs a terminal, but fd .* is not one"):
            TerminalKeyboard(fd=read_end)
    finally:
        os.close(read_end)
        os.close(write_end)
    with pytest.raises(InputDeviceError, match=r"input.path: terminal '/dev/pts/999999' does not exist"):
        TerminalKeyboard(path="/dev/pts/999999")
