"""The low-level stream over a serial port (pyserial): USB-serial/RS-485 bridges to a bench rig
or a microcontroller. Any pyserial URL works (`/dev/ttyUSB0`, `loop://`, `socket://host:port`).

Bandwidth decides the rate: a LowCmd_ frame is 1015 bytes, a LowState_ frame 2103, so 500 Hz each
way needs ~16 Mbit/s; at 921600 baud plan for ~40 Hz, or bridge only what the rig has.
"""

from __future__ import annotations

import errno
import os
import select

from g1_control.errors import TransportError
from g1_control.hardware.links.base import Side
from g1_control.hardware.links.stream import StreamLink


class SerialLink(StreamLink):
    def __init__(self, side: Side, port, baudrate: int = 921600):
        """port: a pyserial URL/device path, or an already open pyserial-like object."""
        super().__init__(side)
        if isinstance(port, str):
            import serial

            try:
                self.port = serial.serial_for_url(port, baudrate=baudrate, timeout=0)
            except (serial.SerialException, ValueError) as exc:
                raise TransportError(f"cannot open serial port '{port}': {exc}") from None
            self.name = port
        else:
            self.port, self.name = port, getattr(port, "name", None) or type(port).__name__

    def describe(self) -> str:
        return f"serial ({self.name})"

    def _write(self, data: bytes) -> None:
        self.port.write(data)

    def _read(self, timeout_s: float) -> bytes:
        if not self.port.in_waiting and timeout_s > 0:
            if _has_fd(self.port):
                select.select([self.port.fileno()], [], [], timeout_s)
            else:  # loop:// and socket:// have no descriptor: use pyserial's own timed read
                self.port.timeout = timeout_s
                first = self.port.read(1)
                self.port.timeout = 0
                return first + self.port.read(self.port.in_waiting) if first else b""
        waiting = self.port.in_waiting
        return self.port.read(waiting) if waiting else b""

    def close(self) -> None:
        self.port.close()


def _has_fd(port) -> bool:
    try:
        port.fileno()
        return True
    except (AttributeError, OSError, ValueError, NotImplementedError):  # loop://, socket:// have none
        return False


class PtyPort:
    """The controlling (master) end of a pseudo-terminal with the slice of pyserial's interface a
    SerialLink uses; the other end is a real tty pyserial opens by path. Stands in for the
    microcontroller side of a serial bridge in tests and emulators."""

    def __init__(self, master_fd: int):
        self.fd = master_fd
        os.set_blocking(master_fd, False)
        self.name = f"pty-master-fd{master_fd}"
        self._pending = b""

    @property
    def in_waiting(self) -> int:
        if select.select([self.fd], [], [], 0)[0]:
            try:
                self._pending += os.read(self.fd, 65536)
            except BlockingIOError:
                pass
            except OSError as exc:
                if exc.errno != errno.EIO:
                    raise
                # EIO: nobody holds the tty end (closed or not opened yet), as on an unplugged cable.
        return len(self._pending)

    def read(self, n: int) -> bytes:
        self.in_waiting  # noqa: B018  (pulls what the kernel holds)
        data, self._pending = self._pending[:n], self._pending[n:]
        return data

    def fileno(self) -> int:
        return self.fd

    def write(self, data: bytes) -> int:
        view = memoryview(data)
        while view:
            select.select([], [self.fd], [], 1.0)
            try:
                written = os.write(self.fd, view)
            except BlockingIOError:
                continue
            view = view[written:]
        return len(data)

    def close(self) -> None:
        os.close(self.fd)


def open_pty_pair(baudrate: int = 921600):
    """(tty path end as a pyserial Serial, master end as a PtyPort), both raw."""
    import pty
    import tty

    import serial

    master, slave = pty.openpty()
    tty.setraw(slave)
    path = os.ttyname(slave)
    tty_end = serial.Serial(path, baudrate=baudrate, timeout=0)
    os.close(slave)  # pyserial holds its own descriptor of the tty
    return tty_end, PtyPort(master)
