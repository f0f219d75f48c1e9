"""Backend over any robot link: the host side of the G1 low-level protocol.

A writer thread resends the latest LowCmd_ at a fixed rate (500 Hz, as the robot expects a steady
stream, whatever rate the controller runs at); a reader thread decodes every LowState_, checks its
CRC and keeps the newest valid one. Every command carries a fresh CRC and the mode_machine accepted
at reset (the expected one): a state that reports another one (a spoofing publisher, a variant
change) is never echoed back to the motors. The reader also watches the link's peers: more than
one writer of LowState_ (by sender, and where DDS discovery can tell, by publication), or another
writer of LowCmd_, is reported as `peer_fault`, which the safety layer trips on. close() leaves a
damping command streaming for a moment before the stream stops, so the last thing the robot
heard is "damp".
"""

from __future__ import annotations

import logging
import threading
import time
from collections import deque
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from g1_control.errors import (
    CrcMismatchError,
    InvalidCommandError,
    MalformedMessageError,
    RobotNotConnectedError,
    VariantMismatchError,
)
from g1_control.hardware.links.base import Link
from g1_control.hardware.unitree.conversions import (
    lowstate_to_robot_state,
    motor_command_to_lowcmd,
    variant_of,
)
from g1_control.hardware.unitree.messages import LOWCMD_TOPIC, LOWSTATE_TOPIC, LowState
from g1_control.hardware.unitree.simulators import RejectedSample, SimulatorProfile, UnsetFields
from g1_control.interfaces import Backend
from g1_control.robot import g1
from g1_control.types import MotorCommand, RobotState

log = logging.getLogger(__name__)

PEER_CHECK_PERIOD_S = 0.5
"""How often the reader thread asks the link's discovery about other writers."""


@dataclass
class LinkStats:
    commands_sent: int
    states_received: int
    bad_crc: int
    malformed: int
    bad_frames: int
    state_rate_hz: float
    """Valid states per second over the last second."""
    command_rate_hz: float
    command_period_p99_s: float
    last_state_age_s: float
    state_senders: int = 0
    """Distinct writers whose LowState_ arrived within the last second (0 where the link cannot tell)."""
    state_writers: int | None = None
    """Writers of the state topic known to discovery (None where the link has no discovery)."""
    command_writers: int | None = None
    """Other writers of the command topic known to discovery (None where the link has no discovery)."""
    command_ttl_s: float | None = None
    """A command older than this is resent in its hold form (None: the latest command, as it is, forever)."""
    holds: int = 0
    """How many times a command outlived command_ttl_s and its hold form took over (host stalls)."""
    commands_held: int = 0
    """LowCmd_ messages sent in the hold form."""


@dataclass
class _Hold:
    """The hold form of the latest command (no feedforward torque, zero velocity target), encoded by the
    writer thread the first time it is needed (the control thread pays nothing for it)."""

    command: MotorCommand
    mode_machine: int
    since_s: float
    """When the command it holds was written (time.monotonic())."""
    payload: bytes | None = None
    sent: int = 0


class LinkBackend(Backend):
    """Wall-clock backend speaking LowCmd_/LowState_ over `link` (host side)."""

    lockstep = False
    release_motion_service: bool = False
    """Opening the link releases the robot's built-in motion service first (UnitreeDDSBackend)."""
    released_modes: Sequence[str] = ()
    """The motion-service modes that were released (UnitreeDDSBackend), for the deploy report."""
    sees_peers: bool = True
    """The link can tell its peers (peers(), refresh_peers()): the deploy preflight checks them."""

    def __init__(self, link: Link, *, command_rate_hz: float = 500.0, mode_pr: int = 0,
                 expected_mode_machine: int | None = None, connect_timeout_s: float = 2.0,
                 close_damping_s: float = 0.2, damping_kd: float = 2.0, simulator: SimulatorProfile | None = None,
                 command_ttl_s: float | None = None):
        """simulator: one of Unitree's simulators (hardware/unitree/simulators.py), whose LowState_
        leaves fields unset that a robot fills: those are filled in here (needs expected_mode_machine).
        command_ttl_s: a command not renewed within this time is resent in its hold form (module
        docstring); None: resent as it is until the next one."""
        if link.side != "host":
            raise ValueError("LinkBackend needs the host side of a link")
        if not command_rate_hz > 0:
            raise ValueError(f"command_rate_hz must be positive; got {command_rate_hz}")
        if mode_pr not in (0, 1):
            raise ValueError(f"mode_pr must be 0 or 1; got {mode_pr}")
        if command_ttl_s is not None and not command_ttl_s > 0:
            raise ValueError(f"command_ttl_s must be positive (or None); got {command_ttl_s}")
        self.link = link
        self.command_ttl_s = command_ttl_s
        self.command_period_s = 1.0 / command_rate_hz
        self.mode_pr = mode_pr
        self.expected_mode_machine = expected_mode_machine
        self.connect_timeout_s = connect_timeout_s
        self.close_damping_s = close_damping_s
        self.damping_kd = damping_kd
        self._lock = threading.Lock()
        self._state: RobotState | None = None
        self._state_event = threading.Event()
        self._payload: bytes | None = None
        self._hold: _Hold | None = None
        """The latest command's hold form while it differs from the command (else None)."""
        self._holds = 0
        self._held_sends = 0
        self._bad_crc = 0
        self._malformed = 0
        self._received = 0
        self._state_times: deque[float] = deque(maxlen=2000)
        self._send_times: deque[float] = deque(maxlen=2000)
        self.mode_machine: int | None = None
        """The mode_machine every command carries, accepted at reset() (None before)."""
        self._senders: dict[int, float] = {}
        self._peer_counts: dict[str, int] | None = None
        self._peers_checked_s = 0.0
        self._stop = threading.Event()
        self._threads: list[threading.Thread] = []
        self._closed = False
        if simulator is not None and expected_mode_machine is None:
            raise ValueError(f"simulator {simulator.name}: needs expected_mode_machine (what a mode_machine of 0 means)")
        self.unset_fields = None if simulator is None else UnsetFields(simulator, int(expected_mode_machine or 0))
        """The simulator's unset LowState_ fields, filled (None: a robot, every field checked)."""
        self.rejected_sample: RejectedSample | None = None
        """The latest LowState_ dropped for its CRC, decoded unchecked (for the preflight's hints)."""
        self._start()

    # -- Backend ---------------------------------------------------------------------------------
    def reset(self) -> RobotState:
        """Wait for the first valid state (the robot must be talking before anything is sent)."""
        state = self.wait_for_state(self.connect_timeout_s)
        if self.expected_mode_machine is not None and state.mode_machine != self.expected_mode_machine:
            want, got = variant_of(self.expected_mode_machine), variant_of(state.mode_machine)
            raise VariantMismatchError(
                f"the robot reports mode_machine {state.mode_machine} ({got.name}, {got.num_dof} DoF) but this "
                f"setup expects {self.expected_mode_machine} ({want.name}); use a launch file and policy made "
                "for this robot"
            )
        self.mode_machine = int(state.mode_machine)
        return state

    def read_state(self) -> RobotState:
        with self._lock:
            state = self._state
        if state is None:
            raise RobotNotConnectedError(self._no_state_message(None))
        return state

    def write_command(self, command: MotorCommand) -> None:
        state = self.read_state()  # mode_machine must be known before anything goes out
        if not command.is_finite():
            self.damp()
            raise InvalidCommandError("MotorCommand contains NaN or inf; the robot was switched to damping")
        for name in ("q_rad", "dq_radps", "kp", "kd", "tau_nm", "enable"):
            if np.shape(getattr(command, name)) != (g1.NUM_JOINTS,):
                raise InvalidCommandError(
                    f"MotorCommand.{name} has shape {np.shape(getattr(command, name))}; expected ({g1.NUM_JOINTS},)")
        mode_machine = self._command_mode_machine(state)
        payload = self.link.encode(motor_command_to_lowcmd(command, mode_machine=mode_machine, mode_pr=self.mode_pr))
        hold = None
        if self.command_ttl_s is not None and (command.tau_nm.any() or command.dq_radps.any()):
            hold = _Hold(command.hold_form(), mode_machine, time.monotonic())
        with self._lock:
            self._payload = payload
            self._hold = hold

    def damp(self) -> None:
        """Switch the stream to damping (kp 0, kd > 0) at once; needs a known mode_machine."""
        with self._lock:
            state = self._state
        if state is None:
            return  # nothing was ever sent; the robot is not under our control
        msg = motor_command_to_lowcmd(MotorCommand.damping(self.damping_kd), self._command_mode_machine(state),
                                      self.mode_pr)
        payload = self.link.encode(msg)
        with self._lock:
            self._payload = payload
            self._hold = None  # damping is its own hold form

    def _command_mode_machine(self, state: RobotState) -> int:
        """The accepted mode_machine, else the expected one, else (before any reset) the robot's."""
        if self.mode_machine is not None:
            return self.mode_machine
        if self.expected_mode_machine is not None:
            return self.expected_mode_machine
        return state.mode_machine

    def peers(self) -> tuple[int, int | None, int | None]:
        """(writers whose LowState_ arrived within the last second, writers of the state topic known to
        discovery, other writers of the command topic known to discovery); None where unknown."""
        now = time.monotonic()
        with self._lock:
            for sender in [k for k, t in self._senders.items() if now - t > 5.0]:
                del self._senders[sender]
            senders = sum(1 for t in self._senders.values() if now - t <= 1.0)
            counts = self._peer_counts
        if counts is None:
            return senders, None, None
        return senders, counts.get(LOWSTATE_TOPIC), counts.get(LOWCMD_TOPIC)

    @property
    def peer_fault(self) -> str | None:
        # Asked every control tick: the link's description is formatted only for a complaint.
        senders, state_writers, command_writers = self.peers()
        if senders > 1 or (state_writers or 0) > 1:
            n = max(senders, state_writers or 0)
            return (f"{n} publishers on {LOWSTATE_TOPIC} ({senders} sent within the last second) on "
                    f"{self.link.describe()}: another robot or program publishes robot state on this domain and "
                    "partition")
        if command_writers:
            return (f"{command_writers} other writer{'s' if command_writers > 1 else ''} of {LOWCMD_TOPIC} on "
                    f"{self.link.describe()}: another program commands this robot")
        return None

    def refresh_peers(self) -> None:
        """Ask the link's discovery about its peers now (the reader thread does so twice a second)."""
        counts = self.link.peer_writers()
        with self._lock:
            self._peer_counts = counts

    def close(self) -> None:
        if self._closed:
            return
        self._closed = True
        try:
            if self._payload is not None:
                self.damp()
                time.sleep(self.close_damping_s)
        finally:
            self._stop.set()
            for thread in self._threads:
                thread.join(timeout=2.0)
            self.link.close()

    # -- extras ----------------------------------------------------------------------------------
    @property
    def bad_crc(self) -> int:
        """Running count of states dropped for a bad CRC (the safety layer watches its bursts)."""
        with self._lock:
            return self._bad_crc

    def wait_for_state(self, timeout_s: float) -> RobotState:
        if not self._state_event.wait(timeout_s):
            raise RobotNotConnectedError(self._no_state_message(timeout_s))
        return self.read_state()

    def stats(self) -> LinkStats:
        now = time.monotonic()
        with self._lock:
            state_times = [t for t in self._state_times if now - t <= 1.0]
            sends = np.array(self._send_times)
            last = self._state.t_s if self._state is not None else float("nan")
            bad_crc, malformed, received = self._bad_crc, self._malformed, self._received
            holds, held = self._holds, self._held_sends
        senders, state_writers, command_writers = self.peers()
        recent = sends[sends >= now - 1.0] if sends.size else sends
        periods = np.diff(sends) if sends.size > 1 else np.array([float("nan")])
        return LinkStats(
            commands_sent=self.link.counters.sent, states_received=received, bad_crc=bad_crc,
            malformed=malformed, bad_frames=self.link.counters.bad_frames,
            state_rate_hz=float(len(state_times)), command_rate_hz=float(recent.size),
            command_period_p99_s=float(np.percentile(periods, 99)), last_state_age_s=now - last,
            state_senders=senders, state_writers=state_writers, command_writers=command_writers,
            command_ttl_s=self.command_ttl_s, holds=holds, commands_held=held,
        )

    # -- threads ---------------------------------------------------------------------------------
    def _start(self) -> None:
        for target, name in ((self._read_loop, "lowstate-reader"), (self._write_loop, "lowcmd-writer")):
            thread = threading.Thread(target=target, name=name, daemon=True)
            thread.start()
            self._threads.append(thread)

    def _read_loop(self) -> None:
        while not self._stop.is_set():
            now = time.monotonic()
            if now - self._peers_checked_s >= PEER_CHECK_PERIOD_S:
                self._peers_checked_s = now
                self.refresh_peers()
            for payload, sender in self.link.receive_tagged(0.05):
                try:
                    msg = self._decode_state(payload)
                except CrcMismatchError:
                    with self._lock:
                        self._bad_crc += 1
                    continue
                except MalformedMessageError:
                    with self._lock:
                        self._malformed += 1
                    continue
                now = time.monotonic()
                state = lowstate_to_robot_state(msg, now)
                with self._lock:
                    self._state = state
                    self._received += 1
                    if sender is not None:
                        self._senders[sender] = now
                    self._state_times.append(now)
                self._state_event.set()

    def _decode_state(self, payload: bytes) -> LowState:
        try:
            if self.unset_fields is not None:
                return self.unset_fields.decode(self.link, payload)
            return self.link.decode_state(payload)
        except CrcMismatchError:
            msg = self.link.decode_state(payload, verify=False)
            self.rejected_sample = RejectedSample(int(msg.crc), int(msg.tick), int(msg.mode_machine))
            raise

    def _write_loop(self) -> None:
        next_t = time.monotonic()
        while not self._stop.is_set():
            with self._lock:
                payload, hold = self._payload, self._hold
            if hold is not None and time.monotonic() - hold.since_s > (self.command_ttl_s or 0.0):
                payload = self._hold_payload(hold)
            if payload is not None:
                self.link.send(payload)
                with self._lock:
                    self._send_times.append(time.monotonic())
            next_t += self.command_period_s
            delay = next_t - time.monotonic()
            if delay > 0:
                self._stop.wait(delay)
            elif delay < -0.1:
                next_t = time.monotonic()  # fell far behind (host stalled): restart the schedule

    def _hold_payload(self, hold: _Hold) -> bytes | None:
        """The hold form's message (encoded once, counted); the newest payload instead if a new command
        (or damping) replaced the held one while it was encoded."""
        if hold.payload is None:
            hold.payload = self.link.encode(motor_command_to_lowcmd(hold.command, mode_machine=hold.mode_machine,
                                                                    mode_pr=self.mode_pr))
        with self._lock:
            if self._hold is not hold:
                return self._payload
            if hold.sent == 0:
                self._holds += 1
            hold.sent += 1
            self._held_sends += 1
            return hold.payload

    def _no_state_message(self, timeout_s: float | None) -> str:
        waited = f" within {timeout_s:.1f} s" if timeout_s is not None else " yet"
        with self._lock:
            bad = f" ({self._bad_crc} samples had a bad CRC, {self._malformed} were malformed)" \
                if self._bad_crc or self._malformed else ""
        return (f"no valid LowState from the robot{waited} on {self.link.describe()}{bad}; check that the robot "
                "is on and cabled to this interface (or that `g1 sim-robot` runs on the same interface and domain)")
