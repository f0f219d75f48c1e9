"""Dex3HandLink: the host side of the two Dex3-1 hands over Cyclone DDS, beside the body's link.

    hands = Dex3HandLink("lo", 1)                         # `g1 sim-robot --hands dex3` on loopback
    hands.wait_for_state(("left", "right"), 1.0)
    hands.write("right", FingerCommand(q_rad=..., kp=..., kd=...))   # streamed until the next one
    hands.damp()                                          # both hands: kp 0, kd > 0, at once

Per hand: HandCmd_ out on rt/dex3/<side>/cmd, HandState_ in on rt/dex3/<side>/state. A writer
thread resends each hand's latest command at `command_rate_hz` (nothing is sent for a hand before
its first write), a reader thread keeps each hand's newest state and when the samples arrived.
Nothing here vets a command: g1_control/safety/hands.py (GuardedHands) clamps and damps.
close() streams damping for a moment, so the last thing the hands heard is "damp".
"""

from __future__ import annotations

import itertools
import threading
import time
from collections import deque
from dataclasses import dataclass
from typing import Any

from g1_control.errors import MalformedMessageError, RobotNotConnectedError
from g1_control.hardware.links.dds import DdsEntities, domain_participant, import_cyclonedds
from g1_control.robot import dex3
from g1_control.types import FingerCommand, FingerState


@dataclass
class HandStats:
    """One hand's stream as the host saw it."""

    side: str
    states_received: int
    state_rate_hz: float
    """Samples per second over the last `window_s`."""
    distinct_states: int
    """Samples within the window whose contents differed from the sample before them."""
    last_state_age_s: float
    max_gap_s: float
    """The longest time between two samples within the window (inf with fewer than two)."""
    malformed: int
    commands_sent: int


class Dex3HandLink:
    def __init__(self, interface: str, domain_id: int = 0, *, partition: str | None = None,
                 sides: tuple[dex3.Side, ...] = dex3.SIDES, command_rate_hz: float = 100.0,
                 damping_kd: float = dex3.DAMPING_KD, close_damping_s: float = 0.1):
        import_cyclonedds()  # a named error, with the install hint, where the binding is missing
        from cyclonedds.core import InstanceState, ReadCondition, SampleState, ViewState, WaitSet
        from cyclonedds.pub import DataWriter, Publisher
        from cyclonedds.qos import Policy, Qos
        from cyclonedds.sub import DataReader, Subscriber
        from cyclonedds.topic import Topic

        from g1_control.hardware.unitree.hand_idl import HandCmd_, HandState_

        for side in sides:
            dex3.check_side(side)
        if not command_rate_hz > 0:
            raise ValueError(f"command_rate_hz must be positive; got {command_rate_hz}")
        if not damping_kd > 0:
            raise ValueError(f"damping_kd must be positive (damping needs kd > 0); got {damping_kd}")
        self.interface, self.domain_id, self.partition, self.sides = interface, int(domain_id), partition, sides
        self.command_period_s = 1.0 / command_rate_hz
        self.damping_kd, self.close_damping_s = damping_kd, close_damping_s
        # Made, used and deleted under the process-wide DDS entity lock (hardware/links/dds.py: DdsEntities);
        # closed at interpreter exit (damping first) if nobody closed the link.
        self._dds = DdsEntities(on_exit=self.close)
        with self._dds.lock():
            participant = self._dds.add("participant", domain_participant(interface, self.domain_id))
            group_qos = Qos(Policy.Partition([partition])) if partition else None
            publisher = self._dds.add("publisher", Publisher(participant, qos=group_qos))
            subscriber = self._dds.add("subscriber", Subscriber(participant, qos=group_qos))
            self._dds.add("waitset", WaitSet(participant))
            for side in sides:
                self._dds.add(f"writer:{side}", DataWriter(publisher, Topic(participant, dex3.cmd_topic(side),
                                                                            HandCmd_)))
                reader = self._dds.add(f"reader:{side}", DataReader(
                    subscriber, Topic(participant, dex3.state_topic(side), HandState_),
                    qos=Qos(Policy.Reliability.BestEffort, Policy.History.KeepLast(16))))
                self._dds.add(f"condition:{side}",
                              ReadCondition(reader, SampleState.Any | ViewState.Any | InstanceState.Any))
                self._dds.attach("waitset", f"condition:{side}")
        self._lock = threading.Lock()
        self._commands: dict[str, Any] = {}
        self._last_command: dict[str, FingerCommand] = {}
        self._states: dict[str, FingerState] = {}
        self._arrivals: dict[str, deque[tuple[float, bool]]] = {s: deque(maxlen=4000) for s in sides}
        self._last_sample: dict[str, Any] = {}
        self._changed_s: dict[str, float] = {}
        self._received: dict[str, int] = dict.fromkeys(sides, 0)
        self._malformed: dict[str, int] = dict.fromkeys(sides, 0)
        self._sent: dict[str, int] = dict.fromkeys(sides, 0)
        self._state_events: dict[str, threading.Event] = {s: threading.Event() for s in sides}
        self._stop = threading.Event()
        self._closed = False
        self._threads = [threading.Thread(target=self._read_loop, name="dex3-reader", daemon=True),
                         threading.Thread(target=self._write_loop, name="dex3-writer", daemon=True)]
        for thread in self._threads:
            thread.start()

    def describe(self) -> str:
        where = f"interface {self.interface}, domain {self.domain_id}"
        return f"Dex3-1 hands over DDS ({where}{', partition ' + self.partition if self.partition else ''})"

    # -- commands --------------------------------------------------------------------------------
    def write(self, side: dex3.Side, command: FingerCommand) -> None:
        """Stream `command` to hand `side` from now on (as given: GuardedHands vets it first)."""
        from g1_control.hardware.unitree.hand_messages import finger_command_to_handcmd

        self._check_known(side)
        sample = finger_command_to_handcmd(command)
        with self._lock:
            self._commands[side] = sample
            self._last_command[side] = command.copy()

    def damp(self, sides: tuple[dex3.Side, ...] | None = None) -> None:
        """Switch the stream of `sides` (default: every hand) to damping: kp 0, kd > 0."""
        for side in sides or self.sides:
            self.write(side, FingerCommand.damping(self.damping_kd))

    def last_command(self, side: dex3.Side) -> FingerCommand | None:
        """The command hand `side` is being streamed (None before the first)."""
        with self._lock:
            cmd = self._last_command.get(side)
        return None if cmd is None else cmd.copy()

    # -- states ----------------------------------------------------------------------------------
    def read(self, side: dex3.Side) -> FingerState | None:
        """Hand `side`'s newest state (None before the first)."""
        self._check_known(side)
        with self._lock:
            return self._states.get(side)

    def wait_for_state(self, sides: tuple[dex3.Side, ...], timeout_s: float) -> dict[str, FingerState]:
        """The newest state of each of `sides`; RobotNotConnectedError naming the silent hands."""
        end = time.monotonic() + timeout_s
        for side in sides:
            self._check_known(side)
            self._state_events[side].wait(max(0.0, end - time.monotonic()))
        silent = [s for s in sides if not self._state_events[s].is_set()]
        if silent:
            raise RobotNotConnectedError(
                f"no HandState_ from the {' and '.join(silent)} Dex3-1 hand within {timeout_s:.1f} s on "
                f"{', '.join(dex3.state_topic(s) for s in silent)} ({self.describe()}): check that the hand is "
                "connected and powered (or that `g1 sim-robot --hands dex3` runs on the same interface and domain)")
        return {s: self._states[s] for s in sides}

    def last_change_s(self, side: dex3.Side) -> float:
        """time.monotonic() of the newest HandState_ of `side` whose contents differed from the one
        before it (-inf before the first): a live hand's noisy current and torque readings change
        every sample, a frozen hand's do not."""
        with self._lock:
            return self._changed_s.get(side, float("-inf"))

    def stats(self, side: dex3.Side, window_s: float = 1.0) -> HandStats:
        self._check_known(side)
        now = time.monotonic()
        with self._lock:
            arrivals = [(t, changed) for t, changed in self._arrivals[side] if now - t <= window_s]
            state = self._states.get(side)
            received, malformed, sent = self._received[side], self._malformed[side], self._sent[side]
        times = [t for t, _ in arrivals]
        gaps = [b - a for a, b in itertools.pairwise(times)]
        return HandStats(side, received, len(arrivals) / window_s, sum(changed for _, changed in arrivals),
                         now - state.t_s if state is not None else float("inf"), max(gaps, default=float("inf")),
                         malformed, sent)

    # -- lifetime --------------------------------------------------------------------------------
    def close(self) -> None:
        if self._closed:
            return
        self._closed = True
        try:
            with self._lock:
                streaming = tuple(self._commands)
            if streaming:
                self.damp(streaming)  # type: ignore[arg-type]
                time.sleep(self.close_damping_s)
        finally:
            self._stop.set()
            for thread in self._threads:
                thread.join(timeout=2.0)
            # Under the process-wide lock; a thread that outlived its join finds the entities closed
            # (no write, no take, no wait) and ends at its next look at the stop event.
            self._dds.close()

    def __enter__(self) -> Dex3HandLink:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def _check_known(self, side: str) -> None:
        dex3.check_side(side)
        if side not in self.sides:
            raise ValueError(f"this hand link serves {', '.join(self.sides)}; not the {side} hand")

    # -- threads ---------------------------------------------------------------------------------
    def _read_loop(self) -> None:
        from g1_control.hardware.unitree.hand_idl import HandState_
        from g1_control.hardware.unitree.hand_messages import handstate_to_finger_state

        while not self._stop.is_set():
            self._dds.wait("waitset", 0.05)
            for side in self.sides:
                for sample in self._dds.take(f"reader:{side}", 16):  # [] once closed
                    if not isinstance(sample, HandState_):  # an InvalidSample: the hand's writer went away
                        continue
                    now = time.monotonic()
                    try:
                        state = handstate_to_finger_state(sample, now)
                    except (MalformedMessageError, TypeError, ValueError):
                        with self._lock:
                            self._malformed[side] += 1
                        continue
                    with self._lock:
                        changed = sample != self._last_sample.get(side)  # every field, pressures included
                        self._last_sample[side] = sample
                        if changed:
                            self._changed_s[side] = now
                        self._states[side] = state
                        self._received[side] += 1
                        self._arrivals[side].append((now, changed))
                    self._state_events[side].set()

    def _write_loop(self) -> None:
        next_t = time.monotonic()
        while not self._stop.is_set():
            with self._lock:
                commands = list(self._commands.items())
            for side, sample in commands:
                if not self._dds.write(f"writer:{side}", sample):  # closed
                    return
                with self._lock:
                    self._sent[side] += 1
            next_t += self.command_period_s
            delay = next_t - time.monotonic()
            if delay > 0:
                self._stop.wait(delay)
            elif delay < -0.1:
                next_t = time.monotonic()
