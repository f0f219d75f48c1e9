"""A robot link: one side's end of the low-level message stream (host or robot).

Every transport (DDS, CAN, serial) moves the same two messages, LowCmd_ host->robot and LowState_
robot->host; a Link only moves their bytes. Which bytes is the transport's choice (`wire`): DDS
carries the XCDR1 sample, byte links carry the C struct image inside a checksummed frame.
"""

from __future__ import annotations

import threading
from abc import ABC, abstractmethod
from dataclasses import dataclass
from typing import Literal

from g1_control.hardware.unitree.messages import LowCmd, LowState

Side = Literal["host", "robot"]
Wire = Literal["dds", "c"]


@dataclass
class LinkCounters:
    """What a link saw below the message level (frames with a bad checksum never become messages)."""

    sent: int = 0
    received: int = 0
    bad_frames: int = 0
    """Frames dropped by the link itself: checksum failure, truncation, resynchronisation."""


class Link(ABC):
    wire: Wire = "c"

    def __init__(self, side: Side):
        if side not in ("host", "robot"):
            raise ValueError(f"link side must be 'host' or 'robot'; got {side!r}")
        self.side = side
        self.counters = LinkCounters()
        self._counter_lock = threading.Lock()

    @abstractmethod
    def send(self, payload: bytes) -> None:
        """Send one message (a LowCmd_ from the host side, a LowState_ from the robot side)."""

    @abstractmethod
    def receive(self, timeout_s: float) -> list[bytes]:
        """Messages that arrived, waiting up to `timeout_s` for the first one; [] on timeout."""

    def receive_tagged(self, timeout_s: float) -> list[tuple[bytes, int | None]]:
        """As receive(), each message with an id of the writer that sent it where the transport can
        tell writers apart (DDS: the publication handle), else None."""
        return [(payload, None) for payload in self.receive(timeout_s)]

    def peer_writers(self) -> dict[str, int] | None:
        """Writers discovered on this link's two topics, by topic name, not counting this side's own
        writer: {state topic: n, command topic: n}. None where the transport cannot tell (CAN and
        serial carry bytes, not writers; the tick order is checked every tick instead)."""
        return None

    def close(self) -> None:
        """Release the transport."""

    def describe(self) -> str:
        return type(self).__name__

    # Codec helpers: the message form this link's wire carries.
    def encode(self, msg: LowCmd | LowState) -> bytes:
        return msg.to_dds() if self.wire == "dds" else msg.to_c_bytes()

    def decode_command(self, payload: bytes, verify: bool = True) -> LowCmd:
        """Decode a LowCmd_; raises MalformedMessageError, or CrcMismatchError when verify is set."""
        if self.wire == "dds":
            return LowCmd.from_dds(payload, verify=verify)
        return LowCmd.from_c_bytes(payload, verify=verify)

    def decode_state(self, payload: bytes, verify: bool = True) -> LowState:
        if self.wire == "dds":
            return LowState.from_dds(payload, verify=verify)
        return LowState.from_c_bytes(payload, verify=verify)

    def _count(self, name: str, n: int = 1) -> None:
        with self._counter_lock:
            setattr(self.counters, name, getattr(self.counters, name) + n)
