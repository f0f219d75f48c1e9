"""Named errors of the IK retargeter. Each message says what was wrong and what was expected."""

from __future__ import annotations

from g1_control.errors import G1ControlError, RetargetError


class IKError(G1ControlError):
    """Base class of every error g1_control.ik raises on purpose."""


class InvalidFrameError(IKError, KeyError):
    """A frame name the G1 model does not have."""

    def __str__(self) -> str:  # KeyError would otherwise quote the whole message
        return str(self.args[0])


class TaskDefinitionError(IKError, ValueError):
    """A task built with a bad cost, gain or target."""


class LimitDefinitionError(IKError, ValueError):
    """A limit built with bad bounds or frames."""


class InvalidConfigurationError(IKError, ValueError):
    """A robot configuration of the wrong size, or with NaN or a broken quaternion."""


class InvalidReferenceError(IKError, ValueError):
    """A KinematicReference the retargeter cannot act on (NaN, wrong shape, unknown frame)."""


class NoSolutionFound(IKError, RetargetError):
    """The QP solver found no solution (infeasible constraints or iteration limit). Out of the
    retargeter (every relaxation failed too) it is the loop's RetargetError: a typed safety event."""
