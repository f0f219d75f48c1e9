"""What one input device reported since the last poll, before any mapping."""

from __future__ import annotations

from dataclasses import dataclass, field


@dataclass
class InputSnapshot:
    """Device state in the device's own names.

    axes: normalized values as the device reported them (sticks nominally in [-1, 1], triggers
      in [0, 1]); not yet clamped, so the mapping can count NaN and out-of-range values.
    held: buttons down at the end of the interval.
    pressed: every press event in the interval, in order, repeats included. A tap that starts
      and ends between two polls appears here but not in `held`; a terminal keyboard, which
      reports no releases, reports only here.
    """

    axes: dict[str, float] = field(default_factory=dict)
    held: frozenset[str] = frozenset()
    pressed: tuple[str, ...] = ()
