"""Named errors of the motion library. Messages name the file and frame when there is one."""

from __future__ import annotations

from g1_control.errors import G1ControlError


class MotionError(G1ControlError):
    """Base class of every error g1_control.motion raises on purpose."""


class InvalidClipError(MotionError, ValueError):
    """A MotionClip whose arrays disagree in shape, hold NaN, or that has no frames."""


class MotionFormatError(MotionError, ValueError):
    """A motion file that does not follow its format (wrong columns, missing channels, ...)."""


class UnknownJointError(MotionError, KeyError):
    """A joint map or skeleton naming joints the data or the robot does not have."""

    def __str__(self) -> str:
        return str(self.args[0])


class IncompatibleClipsError(MotionError, ValueError):
    """Clips that cannot be combined (different fps, joint or body names)."""
