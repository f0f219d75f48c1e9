"""Declarative policy observations: named terms, scales, concatenation order, history.

A policy's spec lists its terms in the order the network expects them. (The holosoma policies
concatenate in alphabetical order of the term names, not in the order their config lists them;
writing the order down explicitly is what prevents that trap.)
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from g1_control.errors import PolicyMismatchError
from g1_control.robot.g1 import NUM_JOINTS

TERM_DIMS = {
    "actions": NUM_JOINTS,          # previous raw network output
    "base_ang_vel": 3,              # IMU gyro, base frame (rad/s)
    "command_ang_vel": 1,           # yaw rate command (rad/s)
    "command_lin_vel": 2,           # vx, vy command in the heading frame (m/s)
    "cos_phase": 2,                 # gait phase of each foot
    "sin_phase": 2,
    "dof_pos": NUM_JOINTS,          # q - default q (rad)
    "dof_vel": NUM_JOINTS,          # dq (rad/s)
    "projected_gravity": 3,         # gravity direction in the base frame (unit vector)
}


@dataclass(frozen=True)
class ObsTerm:
    name: str
    scale: float = 1.0

    @property
    def dim(self) -> int:
        return TERM_DIMS[self.name]


@dataclass
class ObservationSpec:
    terms: tuple[ObsTerm, ...]
    history: int = 1
    """Frames stacked per term (oldest first); 1 = current frame only."""

    @classmethod
    def from_dict(cls, d: dict, where: str = "observation") -> ObservationSpec:
        terms = []
        for i, t in enumerate(d.get("terms") or []):
            if isinstance(t, str):
                t = {"name": t}
            name = t.get("name")
            if name not in TERM_DIMS:
                raise PolicyMismatchError(
                    f"{where}.terms[{i}]: unknown observation term {name!r}; known: {', '.join(sorted(TERM_DIMS))}"
                )
            unknown = set(t) - {"name", "scale"}
            if unknown:
                raise PolicyMismatchError(f"{where}.terms[{i}] ({name}): unknown keys {sorted(unknown)}")
            terms.append(ObsTerm(name, float(t.get("scale", 1.0))))
        if not terms:
            raise PolicyMismatchError(f"{where}.terms is empty: a policy needs at least one observation term")
        history = int(d.get("history", 1))
        if history < 1:
            raise PolicyMismatchError(f"{where}.history must be >= 1, got {history}")
        return cls(tuple(terms), history)

    @property
    def frame_dim(self) -> int:
        return sum(t.dim for t in self.terms)

    @property
    def dim(self) -> int:
        return self.frame_dim * self.history


@dataclass
class ObservationBuilder:
    """Concatenates scaled terms into a preallocated float32 vector (no allocation per call)."""

    spec: ObservationSpec
    _frame: np.ndarray = field(init=False)
    _stack: np.ndarray = field(init=False)
    _slices: list[tuple[str, slice, float]] = field(init=False)

    def __post_init__(self) -> None:
        self._stack = np.zeros((1, self.spec.dim), dtype=np.float32)
        # With no history the frame is the observation itself (no copy per call).
        self._frame = self._stack[0] if self.spec.history == 1 else np.zeros(self.spec.frame_dim, dtype=np.float32)
        self._slices, start = [], 0
        for term in self.spec.terms:
            self._slices.append((term.name, slice(start, start + term.dim), term.scale))
            start += term.dim
        # Per term: its slice of the frame (a view), expected shape, and scale (None for 1: no multiply).
        self._views = [(name, self._frame[sl], (sl.stop - sl.start,), None if scale == 1.0 else np.float32(scale))
                       for name, sl, scale in self._slices]
        self._filled = False

    def reset(self) -> None:
        self._filled = False

    def build(self, values: dict[str, np.ndarray]) -> np.ndarray:
        """Observation (1, dim) from raw term values (unscaled), history per term, oldest first."""
        for name, view, shape, scale in self._views:
            value = values[name]
            if (value.shape if isinstance(value, np.ndarray) else np.shape(value)) != shape:
                raise PolicyMismatchError(
                    f"observation term '{name}' has shape {np.shape(value)}; expected {shape}"
                )
            view[:] = value
            if scale is not None:
                view *= scale
        h = self.spec.history
        if h == 1:
            return self._stack
        # Per-term history: [term_a(t-h+1..t), term_b(t-h+1..t), ...]
        flat = self._stack[0]
        offset = 0
        for _, sl, _ in self._slices:
            width = sl.stop - sl.start
            block = flat[offset:offset + width * h].reshape(h, width)
            if not self._filled:
                block[:] = self._frame[sl]
            else:
                block[:-1] = block[1:]
                block[-1] = self._frame[sl]
            offset += width * h
        self._filled = True
        return self._stack
