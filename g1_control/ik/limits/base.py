"""What every IK limit shares: it turns "do not go there" into linear constraints on the step dq.

A limit returns either a box on dq itself (`BoxBounds`, cheap: solvers treat it specially) or
rows `lower <= A dq <= upper` (`RowConstraint`, equality when `equality`). dq is the tangent
step taken over one tick of `dt_s` seconds, so velocity limits scale with dt.
"""

from __future__ import annotations

import abc
from dataclasses import dataclass

import numpy as np

from g1_control.ik.configuration import Configuration

INF = 1e30
"""Bound meaning "unbounded" (what QP solvers such as daqp take for infinity)."""


@dataclass
class BoxBounds:
    lower: np.ndarray
    """(nv,) lower bound on dq."""
    upper: np.ndarray
    """(nv,) upper bound on dq."""


@dataclass
class RowConstraint:
    matrix: np.ndarray
    """(m, nv)."""
    lower: np.ndarray
    """(m,)"""
    upper: np.ndarray
    """(m,); equal to lower for an equality."""
    equality: bool = False


class Limit(abc.ABC):
    @abc.abstractmethod
    def compute(self, configuration: Configuration, dt_s: float) -> BoxBounds | RowConstraint | None:
        """Constraint on dq at this configuration, or None when the limit is inactive."""
