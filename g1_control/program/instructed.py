"""Typed instructions on a teleop keyboard: a line becomes a program that drives the robot until
it ends or the operator takes over.

    device = InstructedInput(TerminalKeyboard(...), world)   # launch/inputs.py wraps keyboards
    '/' walk forward 2 m and turn left <Enter>               # parsed, printed, run

While a program runs, motion comes from it and buttons from the operator's device; any operator
velocity, stop, damp or e-stop cancels it (the device's own stop semantics still apply). A line
that does not parse prints the parser's error (the unknown word and the closest known ones) and
nothing moves. With `confirm` (a real robot: g1 deploy), the program is printed and runs only
after the operator types "y" and Enter: free text never moves a robot unseen.
"""

from __future__ import annotations

from collections.abc import Callable

from g1_control.interfaces import InputDevice, LineInput
from g1_control.program.device import ProgramInput, StepRecord, describe_record
from g1_control.program.exceptions import InstructionError, ProgramError
from g1_control.program.language.parser import InstructionParser
from g1_control.program.program import Program
from g1_control.program.world import World
from g1_control.types import Button, Command, ExecutionFeedback

_CANCELLING = frozenset({Button.STOP, Button.DAMP, Button.ESTOP})
_YES = ("y", "yes")


def _print(text: str) -> None:
    print(text.replace("\n", "\r\n"), end="\r\n", flush=True)  # the terminal is in raw-like mode


class InstructedInput(InputDevice):
    """See the module docstring. `inner`: the operator's keyboard (lines typed, begin_line for `confirm`)."""

    def __init__(self, inner: LineInput, world: World | None = None, *, pose: str = "estimator",
                 confirm: bool = False, say: Callable[[str], None] = _print) -> None:
        self.inner = inner
        self.world = world or World()
        self.pose = pose
        self.confirm = confirm
        self.say = say
        self.parser = InstructionParser.for_places(self.world.names()) if self.world.places else InstructionParser()
        self.active: ProgramInput | None = None
        self.pending: Program | None = None
        """A parsed program waiting for the operator's "y" (confirm)."""
        self.finished: list[ProgramInput] = []
        self._feedback: ExecutionFeedback | None = None

    # -- the operator device, passed through -------------------------------------------------
    @property
    def lost(self) -> bool:
        return self.inner.lost

    @property
    def lost_reason(self) -> str | None:
        return self.inner.lost_reason

    def button_chords(self, action: str) -> list[str]:
        return self.inner.button_chords(action)

    def close(self) -> None:
        self.inner.close()

    def observe(self, feedback: ExecutionFeedback) -> None:
        """The loop's feedback record: passed to the operator's device and to each program run."""
        self._feedback = feedback
        self.inner.observe(feedback)
        if self.active is not None:
            self.active.observe(feedback)

    # -- the tick ------------------------------------------------------------------------------
    def poll(self, now_s: float) -> Command:
        op = self.inner.poll(now_s)
        line = self.inner.take_line()
        if line is not None:
            self._line(line.strip())
        if self.active is None:
            return op
        moving = op.vx_mps != 0.0 or op.vy_mps != 0.0 or op.wz_radps != 0.0
        if moving or op.buttons & _CANCELLING or self.inner.lost:
            self.say("program cancelled by the operator")
            self._end()
            return op
        command = self.active.poll(now_s)
        command.buttons = op.buttons
        if self.active.done:
            stopped = self.active.runner.stopped
            self.say("program stopped: a step did not complete" if stopped else "program done")
            self._end()
        return command

    def _line(self, line: str) -> None:
        if self.pending is not None:
            program, self.pending = self.pending, None
            if line.lower() in _YES:
                self._start(program)
            else:
                self.say("not run")
            return
        if not line:
            return
        try:
            program = self.parser.parse(line).validate(self.world)
        except (InstructionError, ProgramError) as exc:
            self.say(f"not understood: {exc}")
            return
        self.say(program.describe())
        if self.active is not None:
            self.say("(replaces the program that was running)")
            self._end()
        if self.confirm:
            self.pending = program
            self.say('run it on the robot? type y and Enter (anything else: no)')
            self.inner.begin_line("y/n> ")
            return
        self._start(program)

    def _start(self, program: Program) -> None:
        device = ProgramInput(program, self.world, pose=self.pose, start_delay_s=0.0, on_record=self._record)
        if self._feedback is not None:
            device.observe(self._feedback)
        self.active = device

    def _record(self, record: StepRecord) -> None:
        self.say("  " + describe_record(record))

    def _end(self) -> None:
        if self.active is not None:
            self.finished.append(self.active)
        self.active = None


__all__ = ["InstructedInput"]
