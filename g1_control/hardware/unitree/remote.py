"""The Unitree handheld remote's bytes, as the G1 reports them in LowState_.wireless_remote (40 bytes).

Layout (Unitree's G1 developer docs, "remote control data"; docs/robot_facts.md): bytes 0-1 a
header, bytes 2-3 a little-endian u16 button bitfield (bit i = REMOTE_BUTTON_BITS[i]), then
little-endian f32 lx [4:8], rx [8:12], ry [12:16], L2 analog [16:20], ly [20:24], then 16 idle
bytes. Sticks are nominally in [-1, 1], ly positive forward. The operator side (mapping the
sticks to a Command) is g1_control/teleop/unitree_remote.py.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass

from g1_control.errors import RemoteDecodeError

REMOTE_BUTTON_BITS = ("R1", "L1", "start", "select", "R2", "L2", "F1", "F2",
                      "A", "B", "X", "Y", "up", "right", "down", "left")
"""Bit i of the u16 at bytes 2-3 (little-endian) is button REMOTE_BUTTON_BITS[i]."""

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
