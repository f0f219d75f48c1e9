"""The keyboard of the terminal teleop runs in (local, or over SSH: it only needs a tty).

The terminal is switched to a raw-like mode for the session: no line buffering, no echo, no
flow control (Ctrl-S must not freeze the input), Enter arriving as '\r'. Signals stay on, so
Ctrl-C still interrupts the program and the loop shuts down with the robot damped. The previous
mode is restored on close() and, should close() never run, at interpreter exit.

A terminal reports key presses (and auto-repeat) but never releases, so velocity keys step
virtual axes (mapping `key_axes`) and a key bound to zero_velocity stops. The terminal going
away (SSH dropped: read returns EOF or EIO) makes the device lost.

Line mode: the key bound to `instruction` ('/' by default) stops the robot and opens a line;
what is typed next is text (echoed), Backspace edits, Enter submits it (`take_line()`; the
program input of g1_control/program/instructed.py parses and runs it). In line mode letters
are text, never actions: only named keys bound to estop or damp (Esc by default) still act,
and they also drop the line.
"""

from __future__ import annotations

import atexit
import errno
import os
import select
import sys
import termios
import time
from collections import deque
from collections.abc import Callable

from g1_control.errors import InputDeviceError
from g1_control.interfaces import LineInput
from g1_control.teleop.device import DeviceLost, TeleopDevice
from g1_control.teleop.mapping import LINE_ACTION, MappingConfig
from g1_control.teleop.snapshot import InputSnapshot
from g1_control.types import Button, CommandLimits

_ESCAPE_KEYS = {  # CSI / SS3 sequences of common terminals (xterm, VT220)
    "[A": "up", "[B": "down", "[C": "right", "[D": "left", "OA": "up", "OB": "down", "OC": "right", "OD": "left",
    "[H": "home", "[F": "end", "OH": "home", "OF": "end", "[1~": "home", "[4~": "end", "[2~": "insert",
    "[3~": "delete", "[5~": "page_up", "[6~": "page_down",
}
_CONTROL_KEYS = {"\r": "enter", "\n": "enter", "\t": "tab", " ": "space", "\x7f": "backspace", "\x08": "backspace"}


def decode_keys(text: str) -> tuple[list[str], int]:
    """Key names in `text` (as layouts.KEYBOARD_KEYS names them) and how many were unknown.

    A lone ESC at the end of a read is the Escape key: terminals send an arrow's whole escape
    sequence in one write, so waiting for more bytes would only delay an e-stop bound to Esc.
    """
    keys: list[str] = []
    unknown = 0
    i = 0
    while i < len(text):
        ch = text[i]
        if ch == "\x1b":
            if i + 1 < len(text) and text[i + 1] in "[O":
                j = i + 2
                # A CSI sequence ends at its final byte, 0x40..0x7e.
                while j < len(text) and not ("\x40" <= text[j] <= "\x7e"):
                    j += 1
                name = _ESCAPE_KEYS.get(text[i + 1:j + 1])
                if name:
                    keys.append(name)
                else:
                    unknown += 1
                i = j + 1
                continue
            keys.append("esc")
        elif ch in _CONTROL_KEYS:
            keys.append(_CONTROL_KEYS[ch])
        elif "\x01" <= ch <= "\x1a":
            keys.append(f"ctrl+{chr(ord(ch) + 96)}")
        elif ch.isprintable() and ch.isascii():
            keys.append(ch.lower())
        else:
            unknown += 1
        i += 1
    return keys, unknown


class TerminalKeyboard(TeleopDevice, LineInput):
    kind = "keyboard"

    def __init__(self, mapping: MappingConfig | None = None, limits: CommandLimits | None = None, *,
                 path: str | None = None, fd: int | None = None, where: str = "input",
                 clock: Callable[[], float] = time.monotonic, name: str | None = None,
                 echo: Callable[[str], None] | None = None) -> None:
        super().__init__(mapping or MappingConfig.default("keyboard"), limits, name=name or "keyboard", clock=clock)
        buttons = self.mapper.config.buttons
        self._line_keys = {k for chord, a in buttons.items() if a == LINE_ACTION for k in chord}
        self._line_stop_keys = {k for chord, a in buttons.items() if a in (Button.ESTOP, Button.DAMP)
                                for k in chord if len(k) > 1}
        """Named keys (Esc) that stop the robot even in line mode; letters there are text."""
        self._line: str | None = None
        self.lines: deque[str] = deque()
        self._echo = echo if echo is not None else _stdout_echo
        self._owns_fd = False
        if path is not None:
            try:
                fd = os.open(path, os.O_RDONLY | os.O_NOCTTY | os.O_CLOEXEC)
            except FileNotFoundError:
                raise InputDeviceError(f"{where}.path: terminal {path!r} does not exist") from None
            except OSError as exc:
                raise InputDeviceError(f"{where}.path: cannot open terminal {path!r}: {exc.strerror}") from None
            self._owns_fd = True
        elif fd is None:
            fd = sys.stdin.fileno()
        self._fd = fd
        self.path = path or f"fd {fd}"
        if not os.isatty(fd):
            self._close_fd()
            raise InputDeviceError(
                f"{where}: keyboard input needs a terminal, but {self.path} is not one "
                "(run in an interactive shell or ssh -t; pipes and files cannot drive the keyboard device)")
        self._saved: list | None = termios.tcgetattr(fd)
        """The terminal's attributes to restore (None once restored)."""
        mode = termios.tcgetattr(fd)
        mode[0] &= ~(termios.IXON | termios.IXOFF | termios.ICRNL | termios.INLCR | termios.IGNCR | termios.ISTRIP)
        mode[3] &= ~(termios.ICANON | termios.ECHO | termios.IEXTEN)
        mode[6][termios.VMIN] = 1
        mode[6][termios.VTIME] = 0
        termios.tcsetattr(fd, termios.TCSANOW, mode)
        atexit.register(self._restore)
        self.unknown_keys = 0
        self.keys_read = 0

    def fileno(self) -> int:
        return self._fd

    def _read(self) -> InputSnapshot:
        data = b""
        # select() instead of O_NONBLOCK: the flag would also land on the shell's stdout, which
        # shares the terminal's open file description, and break every later print.
        while select.select([self._fd], [], [], 0.0)[0]:
            try:
                chunk = os.read(self._fd, 1024)
            except InterruptedError:
                continue
            except OSError as exc:
                name = errno.errorcode.get(exc.errno or 0, str(exc.errno))
                raise DeviceLost(f"{self.path}: read failed with {name} ({exc.strerror}): terminal closed?") from None
            if not chunk:
                raise DeviceLost(f"{self.path}: end of input (terminal hung up)")
            data += chunk
        if not data:
            return InputSnapshot()
        keys, unknown = decode_keys(data.decode("utf-8", errors="replace"))
        self.unknown_keys += unknown
        self.keys_read += len(keys)
        if self._line_keys or self._line is not None:
            keys = self._line_mode(keys)
        return InputSnapshot(pressed=tuple(keys))

    # -- line mode ---------------------------------------------------------------------------
    @property
    def typing(self) -> bool:
        """A line is open (keys are text)."""
        return self._line is not None

    def begin_line(self, prompt: str = "> ") -> None:
        """Open a line as the `instruction` key does (e.g. to ask for a confirmation)."""
        self._line = ""
        self._echo("\r\n" + prompt)

    def take_line(self) -> str | None:
        """The oldest submitted line, or None."""
        return self.lines.popleft() if self.lines else None

    def _line_mode(self, keys: list[str]) -> list[str]:
        """Keys typed into a line are consumed; the rest pass on to the mapping."""
        out = []
        for key in keys:
            if self._line is None:
                out.append(key)  # the instruction key itself passes: its action stops the robot
                if key in self._line_keys:
                    self.begin_line()
                continue
            if key in self._line_stop_keys:
                out.append(key)
                self._line = None
                self._echo("  [line dropped]\r\n")
            elif key == "enter":
                self.lines.append(self._line)
                self._line = None
                self._echo("\r\n")
            elif key == "backspace":
                if self._line:
                    self._line = self._line[:-1]
                    self._echo("\b \b")
            elif key == "space" or len(key) == 1:
                ch = " " if key == "space" else key
                self._line += ch
                self._echo(ch)
        return out

    def _restore(self) -> None:
        if self._saved is not None:
            try:
                termios.tcsetattr(self._fd, termios.TCSADRAIN, self._saved)
            except (termios.error, OSError):
                pass  # the terminal is already gone (hung up): nothing left to restore
            self._saved = None
            atexit.unregister(self._restore)

    def _close_fd(self) -> None:
        if self._owns_fd and self._fd >= 0:
            os.close(self._fd)
            self._fd = -1

    def _release(self) -> None:
        self._restore()
        self._close_fd()


def _stdout_echo(text: str) -> None:
    if sys.stdout.isatty():
        sys.stdout.write(text)
        sys.stdout.flush()
