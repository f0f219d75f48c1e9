"""What every teleop input device shares: mapping to a Command, and loss handling.

A device that disconnects (read error, ENODEV, end of stream, stale data) is lost for good:
`lost` turns True, the loss is logged once, and every later poll returns the lost command
(zero velocity + 'damp'). Reconnecting is deliberately not automatic: a robot that was damped
because its operator vanished must not start walking again when a cable wiggles back.
"""

from __future__ import annotations

import logging
import time
from abc import abstractmethod
from collections.abc import Callable

from g1_control.errors import LaunchFileError
from g1_control.interfaces import InputDevice
from g1_control.teleop.mapper import CommandMapper
from g1_control.teleop.mapping import MappingConfig
from g1_control.teleop.snapshot import InputSnapshot
from g1_control.types import Command, CommandLimits

log = logging.getLogger(__name__)


class DeviceLost(Exception):
    """Raised inside a device's read when the device is gone (internal; never escapes poll)."""


class TeleopDevice(InputDevice):
    """Base class: subclasses implement `_read() -> InputSnapshot` (non-blocking; the poll's time
    is `self._now_s`)."""

    kind: str = "device"

    def __init__(self, mapping: MappingConfig, limits: CommandLimits | None = None, *,
                 name: str | None = None, clock: Callable[[], float] = time.monotonic) -> None:
        if mapping.layout.kind != self.kind:
            raise LaunchFileError(f"{type(self).__name__} needs a {self.kind} mapping, got one for a {mapping.layout.kind}")
        self.mapper = CommandMapper(mapping, limits)
        self.name = name or self.kind
        self._clock = clock
        self._now_s = 0.0
        self._lost_reason: str | None = None
        self._closed = False

    @property
    def lost(self) -> bool:
        return self._lost_reason is not None

    def describe(self) -> str:
        return self.name

    def button_chords(self, action: str) -> list[str]:
        return ["+".join(sorted(chord)) for chord, a in self.mapper.config.buttons.items() if a == action]

    @property
    def lost_reason(self) -> str | None:
        return self._lost_reason

    @property
    def stats(self):
        return self.mapper.stats

    def poll(self, now_s: float | None = None) -> Command:
        """The Command for `now_s` (the loop's clock); without it (a device used on its own, as
        `g1 input` does), the device's own clock."""
        self._now_s = self._clock() if now_s is None else now_s
        if not self.lost:
            try:
                snapshot = self._read()
            except DeviceLost as exc:
                self._mark_lost(str(exc))
            else:
                return self.mapper.update(snapshot, self._now_s)
        return self.mapper.lost_command()

    def _mark_lost(self, reason: str) -> None:
        self._lost_reason = reason
        log.warning("input device %s lost: %s; commanding zero velocity and damping", self.name, reason)
        self._release()

    @abstractmethod
    def _read(self) -> InputSnapshot:
        """Everything the device reported since the last call; raise DeviceLost when it is gone."""

    def _release(self) -> None:
        """Give back OS resources (file descriptors, terminal modes)."""

    def close(self) -> None:
        if not self._closed:
            self._closed = True
            self._release()

    def __enter__(self):
        return self

    def __exit__(self, *exc) -> None:
        self.close()
