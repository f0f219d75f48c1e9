"""`g1 doctor`: why "the policy loads but the robot does not move", found before anything is sent.

The most common first-day failures with a G1 are on the network and in the robot's mode: the wrong
NIC (or one without an address on 192.168.123.0/24), a DDS domain that does not match, a firewall
that drops multicast discovery, the built-in controller still running (the debug-mode step missed),
another program already writing rt/lowcmd. The doctor listens and asks; it never writes a command
(the link's command stream stays silent: no LowCmd_ goes out) and never releases the motion service.

Each row is one finding with its fix. It reuses the deploy preflight's robot checks, so what the
doctor calls healthy is what `g1 deploy` will accept.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from g1_control.deploy.preflight import FAIL, NOT_RUN, PASS, SKIP, CheckResult, Preflight, format_table
from g1_control.errors import G1ControlError, RobotNotConnectedError
from g1_control.hardware.links.network import LOOPBACK, ROBOT_SUBNET, interface_table

if TYPE_CHECKING:
    from g1_control.launch.schema import LaunchFile

ROBOT_ROWS = ("state_stream", "variant", "peers", "imu_upright", "joint_limits", "temperatures")
"""The preflight's checks that need nothing but the robot's state (the doctor shows these)."""
ROWS = ("interface", *ROBOT_ROWS, "motion_service")
"""The doctor's findings, in the order it prints them."""
OTHER_DOMAINS = (0, 1)
"""Where a robot (0) or a simulator (1) conventionally publishes, tried when the named domain is silent."""


@dataclass
class DoctorOptions:
    interface: str | None = None
    domain: int | None = None
    partition: str | None = None
    listen_s: float = 3.0
    """How long to wait for the robot's state on each domain tried."""


def diagnose(launch: LaunchFile, options: DoctorOptions, say=print) -> list[CheckResult]:
    """Every finding (interface, robot checks, motion_service, domain), printed as a table by the caller."""
    b = launch.backend
    if b.type != "unitree_dds":
        raise G1ControlError(f"g1 doctor checks a unitree_dds robot link; this launch file's backend is {b.type}")
    if options.interface is not None:
        b.interface = options.interface
    if options.domain is not None:
        b.domain = options.domain
    if options.partition is not None:
        b.partition = options.partition
    b.connect_timeout_s = options.listen_s
    pf = Preflight(frozenset())
    if _check_interface(pf, launch):
        _check_robot(pf, launch, options, say)
    why = "not run: " + ("no usable interface" if pf.results["interface"].status == FAIL else "no robot state")
    found = {name: r for name, r in pf.results.items() if r.status != NOT_RUN}
    return [found.get(name) or CheckResult(name, NOT_RUN, why) for name in ROWS]


def _check_robot(pf: Preflight, launch: LaunchFile, options: DoctorOptions, say) -> None:
    b = launch.backend
    say(f"listening on {b.interface}, DDS domain {b.domain} for {options.listen_s:.0f} s (nothing is sent) ...")
    backend = _listen(launch, b.domain)
    if backend is None:
        _no_robot(pf, launch, options, say)
        return
    try:
        pf.check_robot(backend, launch, None)
        _check_motion_service(pf, launch, backend)
    finally:
        backend.close()


def _check_interface(pf: Preflight, launch: LaunchFile) -> bool:
    from g1_control.deploy.backends import check_link_endpoint

    b = launch.backend
    table = interface_table()
    listed = ", ".join(f"{name} {addr or 'no IPv4'}" for name, addr in table.items())
    try:
        what = check_link_endpoint(b)  # resolves `auto`
    except G1ControlError as exc:
        return pf.record("interface", FAIL, str(exc), overridable=False)
    address = table.get(b.interface or "")
    if b.interface != LOOPBACK and (address is None or address not in ROBOT_SUBNET):
        return pf.record("interface", FAIL, f"{b.interface} has {address or 'no IPv4 address'}, not one on the robot's "
                         f"network {ROBOT_SUBNET}: the robot cannot be reached there. Give the NIC cabled to the robot "
                         f"an address (sudo ip addr add 192.168.123.99/24 dev {b.interface}) or name that NIC "
                         f"(--interface auto finds it). Interfaces: {listed}", overridable=False)
    return pf.record("interface", PASS, what + (f", {address}" if address is not None and "auto" not in what else ""))


def _listen(launch: LaunchFile, domain: int):
    """A silent host link on `domain` that has received the robot's state, or None (closed) after listen_s."""
    from g1_control.deploy.backends import open_robot_backend

    b = launch.backend
    saved, b.domain = b.domain, domain
    try:
        backend = open_robot_backend(b, release_motion_service=False)
    finally:
        b.domain = saved
    try:
        backend.wait_for_state(b.connect_timeout_s)
    except RobotNotConnectedError:
        backend.close()
        return None
    return backend


def _no_robot(pf: Preflight, launch: LaunchFile, options: DoctorOptions, say) -> None:
    b = launch.backend
    for other in (d for d in OTHER_DOMAINS if d != b.domain):
        say(f"nothing on domain {b.domain}; listening on domain {other} ...")
        backend = _listen(launch, other)
        if backend is not None:
            mode = backend.read_state().mode_machine
            backend.close()
            pf.record("state_stream", FAIL, f"no LowState_ on DDS domain {b.domain}, but a robot (mode_machine {mode}) "
                      f"publishes on domain {other}: set backend.domain: {other} (or --domain {other})",
                      overridable=False)
            return
    simulated = b.interface == LOOPBACK
    fix = ("start the emulated robot first (g1 sim-robot, domain 1 on lo)" if simulated else
           "check that the robot is powered and booted (about a minute after power-on), that the cable goes to "
           f"{b.interface}, that a firewall lets UDP multicast through on it (DDS discovery, ports 7400-7500: e.g. "
           "sudo ufw allow in on NIC), and that the robot's own network is up (ping 192.168.123.161)")
    tried = ", ".join(str(d) for d in dict.fromkeys((b.domain, *OTHER_DOMAINS)))
    pf.record("state_stream", FAIL, f"no robot state (rt/lowstate) within {options.listen_s:.1f} s on {b.interface}, "
              f"DDS domains {tried}: " + fix, overridable=False)


def _check_motion_service(pf: Preflight, launch: LaunchFile, backend) -> bool:
    """The deploy preflight's motion_service row (CheckMode only; nothing released)."""
    return pf.check_motion_service(backend, launch)


def table(results: list[CheckResult]) -> str:
    return format_table(results)


def healthy(results: list[CheckResult]) -> bool:
    return all(r.status in (PASS, SKIP) for r in results)
