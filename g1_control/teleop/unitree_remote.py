"""The Unitree handheld remote as an operator input device. Its bytes ride in
LowState_.wireless_remote; their layout is g1_control/hardware/unitree/remote.py.

The remote's bytes ride inside the robot's state stream, so the device has no file of its own:
it reads from a `state_source` (called each poll; returns the latest RobotState or raw bytes)
or is pushed bytes with `feed()`. The remote itself reports no disconnection in this layout; what
can be detected is the state stream stopping (no fresh sample within `stale_after_s`), the
source failing, or malformed bytes, and each of those makes the device lost.
"""

from __future__ import annotations

import math
import threading
import time
from collections.abc import Callable

from g1_control.errors import LaunchFileError, RemoteDecodeError
from g1_control.hardware.unitree.remote import (  # noqa: F401  (the wire format, re-exported)
    REMOTE_SIZE,
    RemoteReading,
    decode_wireless_remote,
    encode_wireless_remote,
)
from g1_control.teleop.device import DeviceLost, TeleopDevice
from g1_control.teleop.mapping import MappingConfig
from g1_control.teleop.snapshot import InputSnapshot
from g1_control.types import CommandLimits, RobotState


class UnitreeRemote(TeleopDevice):
    kind = "unitree_remote"

    def __init__(self, mapping: MappingConfig | None = None, limits: CommandLimits | None = None, *,
                 state_source: Callable[[], RobotState | bytes | None] | None = None,
                 stale_after_s: float = 0.25, clock: Callable[[], float] = time.monotonic,
                 name: str | None = None) -> None:
        super().__init__(mapping or MappingConfig.default("unitree_remote"), limits, name=name, clock=clock)
        if not (isinstance(stale_after_s, (int, float)) and math.isfinite(stale_after_s) and stale_after_s > 0):
            raise LaunchFileError(f"stale_after_s is {stale_after_s!r}; expected a positive number of seconds")
        self._source = state_source
        self.stale_after_s = float(stale_after_s)
        self._last_fresh_s: float | None = None
        """Poll time at which the latest fresh sample was seen (None before the first poll)."""
        self._fresh_samples = 0
        self._seen_samples = 0
        self._last_tick: int | None = None
        self._last_bytes: bytes | None = None
        self._reading = RemoteReading(frozenset(), 0.0, 0.0, 0.0, 0.0, 0.0)
        self._presses: list[str] = []
        # feed() may run on the transport's receive thread while poll() runs on the loop's.
        self._lock = threading.Lock()
        self.decode_errors = 0
        self.samples = 0

    def feed(self, data: bytes) -> None:
        """Push one wireless_remote sample (from a backend's state callback)."""
        try:
            reading = decode_wireless_remote(data)
        except RemoteDecodeError:
            with self._lock:
                self.decode_errors += 1
            return
        with self._lock:
            self._presses.extend(sorted(reading.buttons - self._reading.buttons))
            self._reading = reading
            self._fresh_samples += 1
            self.samples += 1

    def _pull(self, source: Callable[[], RobotState | bytes | None]) -> None:
        try:
            sample = source()
        except Exception as exc:
            raise DeviceLost(f"state source failed: {type(exc).__name__}: {exc}") from None
        if sample is None:
            return
        if isinstance(sample, RobotState):
            # A state whose tick did not advance is the same sample again, not a fresh one.
            if sample.tick == self._last_tick:
                return
            self._last_tick = sample.tick
            data = sample.wireless_remote
        else:
            if sample is self._last_bytes:
                return
            self._last_bytes = sample
            data = sample
        self.feed(data)

    def _read(self) -> InputSnapshot:
        if self._source is not None:
            self._pull(self._source)
        now = self._now_s
        with self._lock:
            # Freshness is judged on the poll's clock, whichever thread fed the sample.
            if self._last_fresh_s is None or self._fresh_samples != self._seen_samples:
                self._seen_samples = self._fresh_samples
                self._last_fresh_s = now
            silent_s = now - self._last_fresh_s
            if silent_s > self.stale_after_s:
                what = f" ({self.decode_errors} malformed samples)" if self.decode_errors else ""
                raise DeviceLost(f"no remote data for {silent_s:.3f} s (limit {self.stale_after_s} s){what}")
            presses, self._presses = tuple(self._presses), []
            reading = self._reading
        return InputSnapshot(axes=reading.axes(), held=reading.buttons, pressed=presses)
