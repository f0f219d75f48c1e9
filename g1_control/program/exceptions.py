"""Named errors of the behaviour program and its text parser."""

from __future__ import annotations

from g1_control.errors import G1ControlError


class ProgramError(G1ControlError, ValueError):
    """A behaviour program that fails validation (bad value, unknown style, missing name, unknown field).

    The message names the step and the field: "step 2 (walk).distance_m: must be > 0, got -1.0"."""


class InstructionError(G1ControlError, ValueError):
    """An English instruction the parser cannot turn into a program."""


class UnknownWordError(InstructionError):
    """An instruction with a word the parser does not know; the message names it and the closest known words."""

    def __init__(self, message: str, word: str, suggestions: tuple[str, ...]) -> None:
        super().__init__(message)
        self.word = word
        self.suggestions = suggestions
