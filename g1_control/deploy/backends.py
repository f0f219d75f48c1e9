"""The robot link a launch file names, as a host-side Backend (wall-clock, 500 Hz command stream).

    backend = open_robot_backend(launch.backend, damping_kd=launch.safety.damping_kd)

unitree_dds: the G1 itself (or `g1 sim-robot` on `lo`); can / serial: bench rigs and bridges
speaking the same LowCmd_/LowState_ stream in checksummed frames (g1_control.hardware).
Nothing is sent until the first write_command: opening a link only listens.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import TYPE_CHECKING, TypedDict

from g1_control.errors import NetworkInterfaceError, TransportError
from g1_control.hardware.links.network import AUTO, LOOPBACK, ROBOT_SUBNET, check_interface, robot_interface
from g1_control.launch.schema import BackendConfig, LaunchFile
from g1_control.robot import g1

if TYPE_CHECKING:
    from g1_control.hardware.link_backend import LinkBackend
    from g1_control.hardware.unitree.simulators import SimulatorProfile


class _HostOptions(TypedDict):
    """The LinkBackend keywords every robot link shares."""

    command_rate_hz: float
    mode_pr: int
    expected_mode_machine: int
    connect_timeout_s: float
    damping_kd: float
    command_ttl_s: float | None


def expected_mode_machine(config: BackendConfig) -> int:
    return next(v.mode_machine for v in g1.VARIANTS.values() if v.name == config.expected_variant)


def simulator_profile(config: BackendConfig) -> SimulatorProfile | None:
    """The backend.simulator profile (None: a robot); BackendConfig.validate has checked the name."""
    from g1_control.hardware.unitree.simulators import SIMULATORS

    return SIMULATORS[config.simulator] if config.simulator is not None else None


def check_link_endpoint(config: BackendConfig) -> str:
    """Raise TransportError unless the link's interface/port exists (and is up); say what was found.

    `interface: auto` (unitree_dds) is resolved in `config` to the one NIC on the robot's network."""
    if config.type == "unitree_dds":
        chosen = ""
        if config.interface == AUTO:  # resolved here, once, for everything after the check
            name, address = robot_interface()
            config.interface, chosen = name, f" (auto: the one NIC on {ROBOT_SUBNET}, {address})"
        check_interface(config.interface or "")
        profile = simulator_profile(config)
        if profile is not None:
            return (f"interface {config.interface} exists and is up (loopback: simulation); backend.simulator "
                    f"{profile.name}: {profile.describe}"
                    + ("" if profile.motion_service else ", no motion service: nothing is released"))
        return f"interface {config.interface} exists and is up{chosen}" + (" (loopback: simulation)" if
                                                                            config.interface == LOOPBACK else "")
    if config.type == "can":
        if config.can_interface != "socketcan":
            return f"{config.can_interface} bus '{config.channel}' (no network interface to check)"
        try:
            check_interface(config.channel or "")
        except NetworkInterfaceError as exc:
            raise NetworkInterfaceError(f"CAN {exc}") from None
        return f"CAN interface {config.channel} exists and is up"
    if config.type == "serial":
        port = config.port or ""
        if "://" in port:
            return f"serial URL {port} (no device file to check)"
        if not Path(port).exists():
            raise TransportError(f"serial port '{port}' does not exist; plug in the bridge or fix backend.port "
                                 f"(ports here: {', '.join(_serial_ports()) or 'none'})")
        if not os.access(port, os.R_OK | os.W_OK):
            raise TransportError(f"serial port '{port}' is not readable and writable by this user "
                                 "(add the user to the 'dialout' group)")
        return f"serial port {port} exists and is accessible"
    raise TransportError(f"backend.type {config.type} is not a robot link; g1 deploy needs unitree_dds, can or serial")


def _serial_ports() -> list[str]:
    return sorted(str(p) for pattern in ("ttyUSB*", "ttyACM*") for p in Path("/dev").glob(pattern))


def command_ttl_s(launch: LaunchFile) -> float | None:
    """How long a motor command lasts on the robot link before its hold form takes over:
    safety.command_hold_ticks tracker ticks (None where it is 0: never)."""
    ticks = launch.safety.command_hold_ticks
    return ticks / launch.rates.tracker_hz if ticks > 0 else None


def open_robot_backend(config: BackendConfig, *, damping_kd: float = 2.0,
                       release_motion_service: bool | None = None,
                       command_ttl_s: float | None = None) -> LinkBackend:
    """The host side of the robot link `config` describes (a LinkBackend; threads running, silent).
    command_ttl_s: see LinkBackend (the deploy passes command_ttl_s(launch))."""
    common: _HostOptions = {
        "command_rate_hz": config.command_rate_hz, "mode_pr": config.mode_pr,
        "expected_mode_machine": expected_mode_machine(config), "connect_timeout_s": config.connect_timeout_s,
        "damping_kd": damping_kd, "command_ttl_s": command_ttl_s}
    if config.type == "unitree_dds":
        from g1_control.hardware.dds_backend import UnitreeDDSBackend

        if not config.interface:  # BackendConfig.validate refuses this in a launch file
            raise TransportError("backend.interface: a unitree_dds backend must name its network interface")
        release = config.release_motion_service if release_motion_service is None else release_motion_service
        profile = simulator_profile(config)
        if profile is not None and not profile.motion_service:
            release = False  # nothing to release: the simulator runs none
        return UnitreeDDSBackend(config.interface, config.domain, partition=config.partition,
                                 release_motion_service=release, simulator=profile, **common)
    from g1_control.hardware.link_backend import LinkBackend

    if config.type == "can":
        from g1_control.hardware.links.can_bus import CanLink

        return LinkBackend(CanLink("host", interface=config.can_interface, channel=config.channel,
                                   fd=config.can_fd), **common)
    if config.type == "serial":
        from g1_control.hardware.links.serial_port import SerialLink

        return LinkBackend(SerialLink("host", config.port, config.baudrate), **common)
    raise TransportError(f"backend.type {config.type} is not a robot link; g1 deploy needs unitree_dds, can or serial")
