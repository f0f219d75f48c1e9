"""The keyboard's line mode ('/' then a typed instruction), through a real pseudo-terminal."""

import os
import select

import pytest

from g1_control.errors import LaunchFileError
from g1_control.teleop.keyboard import TerminalKeyboard
from g1_control.teleop.layouts import LAYOUTS
from g1_control.teleop.mapping import MappingConfig


@pytest.fixture
def keyboard():
    master, slave = os.openpty()
    echoed = []
    mapping = MappingConfig.from_dict({"slew_rate": {"vx": None, "vy": None, "wz": None}}, "m",
                                      layout=LAYOUTS["keyboard"])
    kb = TerminalKeyboard(mapping, path=os.ttyname(slave), clock=lambda: 0.0, echo=echoed.append)
    kb.master, kb.echoed = master, echoed
    yield kb
    kb.close()
    for fd in (master, slave):
        try:
            os.close(fd)
        except OSError:
            pass


def type_keys(kb, data: bytes):
    os.write(kb.master, data)
    assert select.select([kb.fileno()], [], [], 5.0)[0], "the pty never delivered the bytes"


def test_slash_stops_the_robot_and_the_typed_line_is_text(keyboard):
    type_keys(keyboard, b"www")
    assert keyboard.poll().vx_mps == pytest.approx(0.3)
    type_keys(keyboard, b"/")
    cmd = keyboard.poll()
    assert keyboard.typing and cmd.vx_mps == 0.0, "the robot stands while the operator types"
    assert cmd.buttons == frozenset(), "'/' is no Command button"
    # letters bound to actions (x damp, r run, o stop, w forward) are text in a line; Enter submits
    type_keys(keyboard, b"pick up the box, walk forward 2 m\r")
    cmd = keyboard.poll()
    assert cmd.buttons == frozenset() and cmd.vx_mps == 0.0
    assert not keyboard.typing
    assert keyboard.take_line() == "pick up the box, walk forward 2 m"
    assert keyboard.take_line() is None
    assert "".join(keyboard.echoed).endswith("pick up the box, walk forward 2 m\r\n")
    type_keys(keyboard, b"w")  # back to driving
    assert keyboard.poll().vx_mps == pytest.approx(0.1)


def test_backspace_edits_and_a_line_can_span_reads(keyboard):
    type_keys(keyboard, b"/turn lefx")
    keyboard.poll()
    type_keys(keyboard, b"\x7ft\r")
    keyboard.poll()
    assert keyboard.take_line() == "turn left"


def test_escape_in_a_line_is_still_the_estop_and_drops_the_line(keyboard):
    type_keys(keyboard, b"/walk forw")
    keyboard.poll()
    type_keys(keyboard, b"\x1b")
    cmd = keyboard.poll()
    assert cmd.buttons == {"estop"}
    assert not keyboard.typing and keyboard.take_line() is None


def test_begin_line_opens_a_line_for_an_answer(keyboard):
    keyboard.begin_line("y/n> ")
    type_keys(keyboard, b"y\r")
    keyboard.poll()
    assert keyboard.take_line() == "y"
    assert "y/n> " in "".join(keyboard.echoed)


def test_the_instruction_action_is_a_single_keyboard_key():
    with pytest.raises(LaunchFileError, match="single keyboard key"):
        MappingConfig.from_dict({"buttons": {"A": "instruction"}}, "input.device.mapping", layout=LAYOUTS["gamepad"])
