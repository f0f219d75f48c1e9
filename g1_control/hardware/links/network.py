"""Network interface checks: the DDS transport names its interface, always.

Left to choose, Cyclone DDS picks a non-loopback interface and multicasts on it; on a shared host
that is traffic where it must not go, and on the robot it is the wrong NIC. So every DDS link
takes an interface name, and it is checked here before Cyclone sees it.
"""

from __future__ import annotations

import socket
from pathlib import Path

from g1_control.errors import NetworkInterfaceError

LOOPBACK = "lo"
IFF_UP = 0x1


def interface_names() -> list[str]:
    return [name for _, name in socket.if_nameindex()]


def check_interface(name: str) -> None:
    """Raise NetworkInterfaceError unless `name` exists and is up."""
    if not name:
        raise NetworkInterfaceError(
            f"no network interface given; name one explicitly (e.g. '{LOOPBACK}' for simulation, the NIC "
            f"on 192.168.123.0/24 for the robot). Interfaces here: {', '.join(interface_names())}"
        )
    names = interface_names()
    if name not in names:
        raise NetworkInterfaceError(
            f"network interface '{name}' does not exist; interfaces here: {', '.join(names)}. "
            f"Use '{LOOPBACK}' for simulation, or the NIC cabled to the robot"
        )
    flags_file = Path("/sys/class/net") / name / "flags"
    if flags_file.exists() and not int(flags_file.read_text().strip(), 16) & IFF_UP:
        raise NetworkInterfaceError(f"network interface '{name}' is down; bring it up (ip link set {name} up)")
