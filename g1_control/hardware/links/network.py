"""Network interface checks: the DDS transport names its interface, always.

Left to choose, Cyclone DDS picks a non-loopback interface and multicasts on it; on a shared host
that is traffic where it must not go, and on the robot it is the wrong NIC. So every DDS link
takes an interface name, and it is checked here before Cyclone sees it.
"""

from __future__ import annotations

import fcntl
import ipaddress
import socket
import struct
from pathlib import Path

from g1_control.errors import NetworkInterfaceError

LOOPBACK = "lo"
IFF_UP = 0x1
AUTO = "auto"
"""`backend.interface: auto` / `--interface auto`: the one NIC with an address on ROBOT_SUBNET."""
ROBOT_SUBNET = ipaddress.IPv4Network("192.168.123.0/24")
"""The G1's wired network: the robot's computers sit on it, the host needs an address there too."""
SIOCGIFADDR, SIOCGIFNETMASK = 0x8915, 0x891B  # linux/sockios.h


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


def interface_ipv4(name: str) -> ipaddress.IPv4Interface | None:
    """The IPv4 address and prefix of interface `name` (the kernel's primary one), or None without one."""
    request = struct.pack("256s", name.encode()[:15])
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sock:
        try:
            address = fcntl.ioctl(sock.fileno(), SIOCGIFADDR, request)[20:24]
            netmask = fcntl.ioctl(sock.fileno(), SIOCGIFNETMASK, request)[20:24]
        except OSError:  # no IPv4 address (or no such interface)
            return None
    return ipaddress.IPv4Interface(f"{socket.inet_ntoa(address)}/{socket.inet_ntoa(netmask)}")


def interface_table() -> dict[str, ipaddress.IPv4Interface | None]:
    """Every interface here with its IPv4 address (None where it has none)."""
    return {name: interface_ipv4(name) for name in interface_names()}


def robot_interface(table: dict[str, ipaddress.IPv4Interface | None] | None = None,
                    subnet: ipaddress.IPv4Network = ROBOT_SUBNET) -> tuple[str, ipaddress.IPv4Interface]:
    """(name, address) of the one interface with an address on `subnet` (`backend.interface: auto`).

    Raise NetworkInterfaceError naming every interface and its address, and the fix, when there is
    none (the NIC cabled to the robot has no address there yet) or more than one (say which)."""
    table = interface_table() if table is None else table
    on_subnet = {name: addr for name, addr in table.items() if addr is not None and addr in subnet}
    listed = ", ".join(f"{name} {addr or 'no IPv4'}" for name, addr in table.items())
    if not on_subnet:
        raise NetworkInterfaceError(
            f"--interface auto: no interface here has an address on the robot's network {subnet} (interfaces: "
            f"{listed}). Cable the robot to this computer and give that NIC an address there, e.g. "
            f"'sudo ip addr add 192.168.123.99/24 dev NIC && sudo ip link set NIC up' (NIC: the wired one, see "
            "'ip -br link'); for g1 sim-robot use --interface lo")
    if len(on_subnet) > 1:
        raise NetworkInterfaceError(
            f"--interface auto: {len(on_subnet)} interfaces are on the robot's network {subnet} "
            f"({', '.join(f'{n} {a}' for n, a in on_subnet.items())}); name the one cabled to the robot with "
            "--interface NAME (or backend.interface)")
    name, address = next(iter(on_subnet.items()))
    return name, address
