"""The Unitree handheld remote, as the G1 reports it in LowState.wireless_remote (40 bytes).

Layout (Unitree's G1 developer docs, "remote control data"; FACTS.md): bytes 0-1 a header,
bytes 2-3 a little-endian u16 button bitfield (bit i = REMOTE_BUTTON_BITS[i]), then
little-endian f32 lx [4:8], rx [8:12], ry [12:16], L2 analog [16:20], ly [20:24], then 16
idle bytes. Sticks are nominally in [-1, 1], ly positive forward.

The remote's bytes ride inside the robot's state stream, so the device has no file of its own:
it reads from a `state_source` (called each poll; returns the latest RobotState or raw bytes)
or is pushed bytes with `feed()`. The remote itself reports no disconnection in this layout; what
can be detected is the state stream stopping (no fresh sample within `stale_after_s`), the
source failing, or malformed bytes, and each of those makes the device lost.
"""

from __future__ import annotations

import math
import struct
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass

from g1_control.errors import LaunchFileError, RemoteDecodeError
from g1_control.teleop.command_limits import CommandLimits
from g1_control.teleop.device import DeviceLost, TeleopDevice
from g1_control.teleop.layouts import REMOTE_BUTTON_BITS
from g1_control.teleop.mapping import MappingConfig
from g1_control.teleop.snapshot import InputSnapshot
from g1_control.types import RobotState

REMOTE_SIZE = 40
_STRUCT = struct.Struct("<2sH5f16s")  # head, buttons, lx, rx, ry, L2, ly, idle
assert _STRUCT.size == REMOTE_SIZE


@dataclass(frozen=True)
class RemoteReading:
    """One decoded remote sample (values as sent: not clamped, may be NaN)."""

    buttons: frozenset[str]
    lx: float
    rx: float
    ry: float
    l2: float
    ly: float

    def axes(self) -> dict[str, float]:
        return {"lx": self.lx, "ly": self.ly, "rx": self.rx, "ry": self.ry, "L2": self.l2}


def decode_wireless_remote(data: bytes) -> RemoteReading:
    """Decode LowState.wireless_remote; RemoteDecodeError if it is not 40 bytes."""
    if len(data) != REMOTE_SIZE:
        raise RemoteDecodeError(f"wireless_remote has {len(data)} bytes; expected {REMOTE_SIZE}")
    _, bits, lx, rx, ry, l2, ly, _ = _STRUCT.unpack(bytes(data))
    buttons = frozenset(name for i, name in enumerate(REMOTE_BUTTON_BITS) if bits >> i & 1)
    return RemoteReading(buttons, lx, rx, ry, l2, ly)


def encode_wireless_remote(buttons=(), lx: float = 0.0, rx: float = 0.0, ry: float = 0.0, l2: float = 0.0,
                           ly: float = 0.0) -> bytes:
    """The 40 bytes the robot would send (for simulators, emulators and tests)."""
    unknown = set(buttons) - set(REMOTE_BUTTON_BITS)
    if unknown:
        raise RemoteDecodeError(f"unknown remote buttons {sorted(unknown)}; known: {', '.join(REMOTE_BUTTON_BITS)}")
    bits = sum(1 << REMOTE_BUTTON_BITS.index(b) for b in set(buttons))
    return _STRUCT.pack(b"\x00\x00", bits, lx, rx, ry, l2, ly, bytes(16))


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
        self._last_fresh_s = clock()
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
            self._last_fresh_s = self._clock()
            self.samples += 1

    def _pull(self) -> None:
        try:
            sample = self._source()
        except Exception as exc:  # noqa: BLE001 - whatever broke, the operator's link is gone
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
            self._pull()
        with self._lock:
            silent_s = self._clock() - self._last_fresh_s
            if silent_s > self.stale_after_s:
                what = f" ({self.decode_errors} malformed samples)" if self.decode_errors else ""
                raise DeviceLost(f"no remote data for {silent_s:.3f} s (limit {self.stale_after_s} s){what}")
            presses, self._presses = tuple(self._presses), []
            reading = self._reading
        return InputSnapshot(axes=reading.axes(), held=reading.buttons, pressed=presses)
