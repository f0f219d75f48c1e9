"""The Linux evdev wire format and the ioctls a gamepad reader needs, from the kernel's UAPI
headers (linux/input.h, linux/input-event-codes.h). No third-party package: the format is one
fixed-size struct and a handful of ioctl numbers.
"""

from __future__ import annotations

import fcntl
import struct

# struct input_event { struct timeval time; __u16 type; __u16 code; __s32 value; }
# timeval is two C longs: 24 bytes on 64-bit Linux, 16 on 32-bit.
EVENT_FORMAT = "@llHHi"
EVENT_SIZE = struct.calcsize(EVENT_FORMAT)

EV_SYN, EV_KEY, EV_ABS = 0x00, 0x01, 0x03
SYN_REPORT, SYN_DROPPED = 0, 3
KEY_RELEASE, KEY_PRESS, KEY_REPEAT = 0, 1, 2

ABS_X, ABS_Y, ABS_Z, ABS_RX, ABS_RY, ABS_RZ = 0x00, 0x01, 0x02, 0x03, 0x04, 0x05
ABS_GAS, ABS_BRAKE = 0x09, 0x0A
ABS_HAT0X, ABS_HAT0Y = 0x10, 0x11
ABS_CNT = 0x40
KEY_CNT = 0x300

BTN_SOUTH, BTN_EAST, BTN_C, BTN_NORTH, BTN_WEST, BTN_Z = 0x130, 0x131, 0x132, 0x133, 0x134, 0x135
BTN_TL, BTN_TR, BTN_TL2, BTN_TR2 = 0x136, 0x137, 0x138, 0x139
BTN_SELECT, BTN_START, BTN_MODE, BTN_THUMBL, BTN_THUMBR = 0x13A, 0x13B, 0x13C, 0x13D, 0x13E
BTN_DPAD_UP, BTN_DPAD_DOWN, BTN_DPAD_LEFT, BTN_DPAD_RIGHT = 0x220, 0x221, 0x222, 0x223

# struct input_absinfo { __s32 value, minimum, maximum, fuzz, flat, resolution; }
ABSINFO_FORMAT = "@6i"
ABSINFO_SIZE = struct.calcsize(ABSINFO_FORMAT)

_IOC_READ = 2


def _ior(nr: int, size: int) -> int:
    return (_IOC_READ << 30) | (size << 16) | (ord("E") << 8) | nr


EVIOCGVERSION = _ior(0x01, 4)


def EVIOCGABS(code: int) -> int:
    return _ior(0x40 + code, ABSINFO_SIZE)


def EVIOCGKEY(length: int) -> int:
    return _ior(0x18, length)


def EVIOCGBIT(ev_type: int, length: int) -> int:
    return _ior(0x20 + ev_type, length)


def EVIOCGNAME(length: int) -> int:
    return _ior(0x06, length)


def pack_event(ev_type: int, code: int, value: int, t_s: float = 0.0) -> bytes:
    """One input_event as the kernel writes it (for tests, replays and benchmarks)."""
    sec = int(t_s)
    return struct.pack(EVENT_FORMAT, sec, int((t_s - sec) * 1e6), ev_type, code, value)


def syn_report(t_s: float = 0.0) -> bytes:
    return pack_event(EV_SYN, SYN_REPORT, 0, t_s)


def ioctl_buffer(fd: int, request: int, size: int) -> bytes:
    """Run a read ioctl into a fresh buffer; OSError (ENOTTY on a pipe or file) passes through."""
    buf = bytearray(size)
    fcntl.ioctl(fd, request, buf, True)
    return bytes(buf)


def absinfo(fd: int, code: int) -> tuple[int, int, int]:
    """(value, minimum, maximum) of one absolute axis."""
    value, minimum, maximum, *_ = struct.unpack(ABSINFO_FORMAT, ioctl_buffer(fd, EVIOCGABS(code), ABSINFO_SIZE))
    return value, minimum, maximum


def bit_set(bits: bytes, index: int) -> bool:
    return bool(bits[index // 8] >> (index % 8) & 1) if index // 8 < len(bits) else False
