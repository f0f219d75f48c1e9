"""The low-level stream over CAN (python-can): each direction is the framed byte stream of
framing.py cut into CAN data frames under one arbitration id (CAN keeps frames of one id in
order), so a lost or damaged CAN frame costs exactly the stream frame it belonged to.

CAN FD (64-byte frames) is the default: a LowCmd_ is 16 FD frames, 8k frames/s at 500 Hz. Classic
CAN (8 bytes) needs 127 frames per LowCmd_; run it at a bench rate (~50 Hz on 1 Mbit/s).
"""

from __future__ import annotations

from g1_control.errors import TransportError
from g1_control.hardware.links.base import Side
from g1_control.hardware.links.stream import StreamLink

HOST_TO_ROBOT_ID = 0x610
ROBOT_TO_HOST_ID = 0x611
_FD_SIZES = (12, 16, 20, 24, 32, 48, 64)


class CanLink(StreamLink):
    def __init__(self, side: Side, bus=None, *, interface: str | None = None, channel: str | None = None,
                 fd: bool = True, ids: tuple[int, int] = (HOST_TO_ROBOT_ID, ROBOT_TO_HOST_ID), **bus_kwargs):
        """bus: an open python-can Bus, or give interface/channel (e.g. 'socketcan', 'can0'; 'virtual', name)."""
        super().__init__(side)
        import can

        if bus is None:
            if not interface or channel is None:
                raise TransportError("CanLink needs an open bus or both interface and channel (e.g. socketcan, can0)")
            try:
                bus = can.Bus(interface=interface, channel=channel, fd=fd, **bus_kwargs)
            except (can.CanError, OSError, ValueError) as exc:
                raise TransportError(f"cannot open CAN bus {interface}:{channel}: {exc}") from None
        self.bus, self.fd = bus, fd
        self.chunk = 64 if fd else 8
        self._tx_id, self._rx_id = ids if side == "host" else ids[::-1]
        self._message = can.Message

    def describe(self) -> str:
        return f"CAN ({getattr(self.bus, 'channel_info', type(self.bus).__name__)}, {'FD' if self.fd else 'classic'})"

    def _write(self, data: bytes) -> None:
        import can

        for i in range(0, len(data), self.chunk):
            piece = data[i: i + self.chunk]
            if self.fd and len(piece) > 8:
                # CAN FD carries only 12/16/20/24/32/48/64 bytes past 8: zero-pad (the deframer
                # skips bytes between frames).
                piece = piece.ljust(next(n for n in _FD_SIZES if n >= len(piece)), b"\0")
            msg = self._message(arbitration_id=self._tx_id, data=piece,
                                is_extended_id=False, is_fd=self.fd, bitrate_switch=self.fd)
            try:
                self.bus.send(msg)
            except can.CanError as exc:
                raise TransportError(f"CAN send failed on {self.describe()}: {exc}") from None

    def _read(self, timeout_s: float) -> bytes:
        chunks = []
        msg = self.bus.recv(timeout=timeout_s)
        while msg is not None:
            if msg.arbitration_id == self._rx_id and not msg.is_error_frame:
                chunks.append(bytes(msg.data))
            msg = self.bus.recv(timeout=0.0)
        return b"".join(chunks)

    def close(self) -> None:
        self.bus.shutdown()
