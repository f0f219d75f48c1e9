"""Checksummed framing of the low-level stream for byte links (serial, CAN).

    magic 'G1' | kind u8 | seq u16 | length u16 | payload | CRC-32 u32      (little endian)

kind 1 carries a LowCmd_ C image, kind 2 a LowState_ C image (each with the G1's own CRC inside,
checked again above this layer). The frame CRC (zlib's CRC-32) covers kind..payload, so a
corrupted length cannot make the receiver swallow the next frame. After any bad frame the decoder
resynchronises on the next magic; seq gaps count lost frames.
"""

from __future__ import annotations

import struct
import zlib
from dataclasses import dataclass

MAGIC = b"G1"
KIND_LOWCMD = 1
KIND_LOWSTATE = 2
KINDS = (KIND_LOWCMD, KIND_LOWSTATE)
MAX_PAYLOAD = 4096
_HEADER = struct.Struct("<2sBHH")
HEADER_SIZE = _HEADER.size
TRAILER_SIZE = 4
OVERHEAD = HEADER_SIZE + TRAILER_SIZE


def encode_frame(kind: int, seq: int, payload: bytes) -> bytes:
    if kind not in KINDS:
        raise ValueError(f"frame kind must be one of {KINDS}; got {kind}")
    if len(payload) > MAX_PAYLOAD:
        raise ValueError(f"frame payload is {len(payload)} bytes; at most {MAX_PAYLOAD}")
    header = _HEADER.pack(MAGIC, kind, seq & 0xFFFF, len(payload))
    return header + payload + struct.pack("<I", zlib.crc32(header[2:] + payload))


@dataclass
class Frame:
    kind: int
    seq: int
    payload: bytes


@dataclass
class DeframerCounters:
    frames: int = 0
    bad_checksum: int = 0
    bad_header: int = 0
    skipped_bytes: int = 0
    lost: int = 0
    """Frames missing between consecutive sequence numbers."""


class Deframer:
    """Turns an arbitrary chunking of the byte stream back into frames."""

    def __init__(self):
        self._buf = bytearray()
        self.counters = DeframerCounters()
        self._last_seq: dict[int, int] = {}

    def feed(self, data: bytes) -> list[Frame]:
        self._buf += data
        frames: list[Frame] = []
        while True:
            start = self._buf.find(MAGIC)
            if start < 0:
                # Keep a trailing 'G' that may be the first half of the next magic.
                keep = 1 if self._buf[-1:] == MAGIC[:1] else 0
                self.counters.skipped_bytes += len(self._buf) - keep
                del self._buf[: len(self._buf) - keep]
                return frames
            if start:
                self.counters.skipped_bytes += start
                del self._buf[:start]
            if len(self._buf) < HEADER_SIZE:
                return frames
            _, kind, seq, length = _HEADER.unpack_from(self._buf)
            if kind not in KINDS or length > MAX_PAYLOAD:
                self.counters.bad_header += 1
                del self._buf[:1]  # not a frame start after all: look for the next magic
                continue
            end = HEADER_SIZE + length + TRAILER_SIZE
            if len(self._buf) < end:
                return frames
            body = bytes(self._buf[2: HEADER_SIZE + length])
            (checksum,) = struct.unpack_from("<I", self._buf, HEADER_SIZE + length)
            if zlib.crc32(body) != checksum:
                self.counters.bad_checksum += 1
                del self._buf[:1]
                continue
            payload = body[HEADER_SIZE - 2:]
            del self._buf[:end]
            last = self._last_seq.get(kind)
            if last is not None:
                self.counters.lost += (seq - last - 1) & 0xFFFF
            self._last_seq[kind] = seq
            self.counters.frames += 1
            frames.append(Frame(kind, seq, payload))
