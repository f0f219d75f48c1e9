"""StreamLink: a Link over any ordered byte carrier (serial port, CAN frames), using framing.py.

Subclasses move bytes (`_write`, `_read`); this class frames LowCmd_/LowState_ C images, numbers
them, and hands the other side's payloads up, counting everything the checksum rejects.
"""

from __future__ import annotations

from abc import abstractmethod

from g1_control.hardware.links.base import Link, Side
from g1_control.hardware.links.framing import KIND_LOWCMD, KIND_LOWSTATE, Deframer, encode_frame


class StreamLink(Link):
    wire = "c"

    def __init__(self, side: Side):
        super().__init__(side)
        self._out_kind = KIND_LOWCMD if side == "host" else KIND_LOWSTATE
        self._in_kind = KIND_LOWSTATE if side == "host" else KIND_LOWCMD
        self._seq = 0
        self.deframer = Deframer()

    @abstractmethod
    def _write(self, data: bytes) -> None: ...

    @abstractmethod
    def _read(self, timeout_s: float) -> bytes:
        """Bytes that arrived, waiting up to `timeout_s` for the first; b'' on timeout."""

    def send(self, payload: bytes) -> None:
        self._write(encode_frame(self._out_kind, self._seq, payload))
        self._seq = (self._seq + 1) & 0xFFFF
        self._count("sent")

    def receive(self, timeout_s: float) -> list[bytes]:
        data = self._read(timeout_s)
        if not data:
            return []
        before = self.deframer.counters.bad_checksum + self.deframer.counters.bad_header
        frames = self.deframer.feed(data)
        bad = self.deframer.counters.bad_checksum + self.deframer.counters.bad_header - before
        if bad:
            self._count("bad_frames", bad)
        payloads = [f.payload for f in frames if f.kind == self._in_kind]
        self._count("received", len(payloads))
        return payloads
