"""Emulated Dex3-1 hands behind their DDS topics, for `g1 sim-robot --hands dex3`.

Per hand: HandCmd_ read from rt/dex3/<side>/cmd and applied, HandState_ published on
rt/dex3/<side>/state. Each finger joint is a one-degree-of-freedom model (main's MuJoCo G1 has
no hand bodies): reflected inertia FINGER_INERTIA_KGM2 and viscous friction driven by the motor
law tau = tau_ff + kp (q_t - q) + kd (dq_t - dq), clipped to the URDF's effort limit (no torque
from a disabled motor, or before the first command); hard stops at the URDF's position limits.
An object in the hand (`hold_object`) stops each closing joint at a contact angle with a stiff
spring: the torque it takes is the emulator's ground truth (`truth()`), apart from what the hand
reports. Reported tau_est and current carry a little sensor noise, as a live hand's do.

Faults, by name (`inject`): hand_state_frozen (the same sample repeated), hand_silent (no
HandState_), finger_miscalibrated (one finger's reading offset past its limit), clear.
"""

from __future__ import annotations

import threading
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from g1_control.errors import NetworkInterfaceError
from g1_control.hardware.links.dds import DdsEntities, domain_participant, import_cyclonedds
from g1_control.hardware.links.network import LOOPBACK
from g1_control.robot import dex3
from g1_control.types import FingerCommand, FingerState

FINGER_INERTIA_KGM2 = 1e-3
"""Assumed reflected inertia of a finger joint (rotor inertia through the gearbox dominates the
finger's own few grams); the emulator's figure, not a measured one."""
FINGER_FRICTION_NMS = 0.01
CONTACT_STIFFNESS_NM_PER_RAD = 20.0
PHYSICS_DT_S = 0.0005
MISCALIBRATION_RAD = 0.3
HAND_FAULTS = {
    "hand_state_frozen": "HandState_ keeps arriving with the same contents",
    "hand_silent": "no HandState_ (hand unplugged)",
    "finger_miscalibrated": "middle_1 reads 0.3 rad past its closed limit (an encoder offset)",
    "clear": "remove every injected hand fault",
}


@dataclass
class FingerTruth:
    """Ground truth of one emulated hand (what the model did, not what it reported)."""

    q_rad: np.ndarray
    motor_tau_nm: np.ndarray
    contact_tau_nm: np.ndarray
    """Torque the object exerts on each joint (0 where not touching)."""
    max_contact_tau_nm: np.ndarray
    """The largest contact torque each joint saw since the object was placed."""
    max_motor_tau_nm: np.ndarray
    """The largest |motor torque| since the object was placed."""
    last_command: FingerCommand | None


@dataclass
class EmulatedHand:
    """One hand's finger joints under the motor law (all arrays (7,), message order)."""

    side: dex3.Side
    limits: dex3.HandLimits = field(init=False)
    q: np.ndarray = field(default_factory=lambda: np.zeros(dex3.NUM_MOTORS))
    dq: np.ndarray = field(default_factory=lambda: np.zeros(dex3.NUM_MOTORS))
    command: FingerCommand | None = None
    contact_q: np.ndarray | None = None
    """Per joint, the angle where the held object stops it (NaN: the object does not reach it)."""

    def __post_init__(self) -> None:
        self.limits = dex3.hand_limits(self.side)
        self.q = self.limits.open_rad.copy()
        self.motor_tau = np.zeros(dex3.NUM_MOTORS)
        self.contact_tau = np.zeros(dex3.NUM_MOTORS)
        self.max_contact_tau = np.zeros(dex3.NUM_MOTORS)
        self.max_motor_tau = np.zeros(dex3.NUM_MOTORS)

    def step(self, dt_s: float) -> None:
        c = self.command
        if c is None:
            tau = np.zeros(dex3.NUM_MOTORS)
        else:
            tau = c.tau_nm + c.kp * (c.q_rad - self.q) + c.kd * (c.dq_radps - self.dq)
            tau = np.where(c.enable, np.clip(tau, -self.limits.effort_nm, self.limits.effort_nm), 0.0)
        self.motor_tau = tau
        contact = np.zeros(dex3.NUM_MOTORS)
        if self.contact_q is not None:
            sign = self.limits.closing_sign
            past = np.nan_to_num(sign * (self.q - self.contact_q), nan=0.0)
            contact = np.where(past > 0, -sign * CONTACT_STIFFNESS_NM_PER_RAD * past, 0.0)
        self.contact_tau = contact
        self.max_contact_tau = np.maximum(self.max_contact_tau, np.abs(contact))
        self.max_motor_tau = np.maximum(self.max_motor_tau, np.abs(tau))
        # friction implicit (stable at any dt), the rest explicit
        self.dq = (self.dq + dt_s * (tau + contact) / FINGER_INERTIA_KGM2) / (
            1.0 + dt_s * FINGER_FRICTION_NMS / FINGER_INERTIA_KGM2)
        self.q = self.q + dt_s * self.dq
        lo, hi = self.limits.q_min_rad, self.limits.q_max_rad
        stopped = (self.q < lo) | (self.q > hi)
        self.q = np.clip(self.q, lo, hi)
        self.dq = np.where(stopped, 0.0, self.dq)


class Dex3HandsEmulator:
    """Both hands on loopback DDS: a thread steps the finger models in wall-clock time and
    publishes each hand's HandState_ at `state_rate_hz`."""

    def __init__(self, interface: str = LOOPBACK, domain_id: int = 1, partition: str | None = None,
                 state_rate_hz: float = 100.0, sides: tuple[dex3.Side, ...] = dex3.SIDES, seed: int = 0):
        """sides: the hands that exist (a missing hand publishes nothing and hears nothing)."""
        import_cyclonedds()
        from cyclonedds.pub import DataWriter, Publisher
        from cyclonedds.qos import Policy, Qos
        from cyclonedds.sub import DataReader, Subscriber
        from cyclonedds.topic import Topic

        from g1_control.hardware.unitree.hand_idl import HandCmd_, HandState_

        if interface != LOOPBACK:
            raise NetworkInterfaceError(f"the hand emulator runs on loopback only (interface '{LOOPBACK}'); "
                                        f"got '{interface}'")
        self.hands = {s: EmulatedHand(s) for s in sides}
        self.period_s = 1.0 / state_rate_hz
        self.rng = np.random.default_rng(seed)
        self.sides = sides
        # Made, used and deleted under the process-wide DDS entity lock (hardware/links/dds.py: DdsEntities);
        # closed at interpreter exit if nobody closed the emulator.
        self._dds = DdsEntities(on_exit=self.close)
        with self._dds.lock():
            participant = self._dds.add("participant", domain_participant(interface, domain_id))
            group_qos = Qos(Policy.Partition([partition])) if partition else None
            pub = self._dds.add("publisher", Publisher(participant, qos=group_qos))
            sub = self._dds.add("subscriber", Subscriber(participant, qos=group_qos))
            for s in sides:
                self._dds.add(f"writer:{s}", DataWriter(pub, Topic(participant, dex3.state_topic(s), HandState_)))
                self._dds.add(f"reader:{s}", DataReader(sub, Topic(participant, dex3.cmd_topic(s), HandCmd_),
                                                        qos=Qos(Policy.Reliability.BestEffort,
                                                                Policy.History.KeepLast(4))))
        self.frozen: set[str] = set()
        self.silent: set[str] = set()
        self.miscalibrated: set[str] = set()
        self._frozen_sample: dict[str, Any] = {}
        self.commands_applied = dict.fromkeys(sides, 0)
        self.malformed = dict.fromkeys(sides, 0)
        self.states_sent = dict.fromkeys(sides, 0)
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None

    # -- the world around the hands --------------------------------------------------------------
    def hold_object(self, side: dex3.Side, closure: float = 0.5) -> np.ndarray:
        """Put an object in hand `side` that every closing joint touches at `closure` (0 open .. 1
        closed) of its travel; return the contact angles. Resets the recorded maxima."""
        if not 0.0 < closure < 1.0:
            raise ValueError(f"closure must be between 0 and 1 (exclusive); got {closure}")
        hand = self.hands[side]
        lim = hand.limits
        contact = lim.open_rad + closure * (lim.closed_rad - lim.open_rad)
        contact = np.where(lim.closing_sign != 0, contact, np.nan)
        with self._lock:
            hand.contact_q = contact
            hand.max_contact_tau[:] = 0.0
            hand.max_motor_tau[:] = 0.0
        return contact

    def release_object(self, side: dex3.Side) -> None:
        """Take the object out of hand `side`."""
        with self._lock:
            self.hands[side].contact_q = None

    def truth(self, side: dex3.Side) -> FingerTruth:
        hand = self.hands[side]
        with self._lock:
            return FingerTruth(hand.q.copy(), hand.motor_tau.copy(), hand.contact_tau.copy(),
                               hand.max_contact_tau.copy(), hand.max_motor_tau.copy(),
                               None if hand.command is None else hand.command.copy())

    def inject(self, fault: str, side: dex3.Side | None = None) -> float:
        """Apply `fault` (HAND_FAULTS) to `side` (default both); return the time.monotonic()."""
        if fault not in HAND_FAULTS:
            raise ValueError(f"unknown hand fault '{fault}'; known: {', '.join(HAND_FAULTS)}")
        sides = [side] if side is not None else list(self.hands)
        with self._lock:
            for s in sides:
                if fault == "clear":
                    self.frozen.discard(s)
                    self.silent.discard(s)
                    self.miscalibrated.discard(s)
                    self._frozen_sample.pop(s, None)
                elif fault == "hand_state_frozen":
                    self.frozen.add(s)
                elif fault == "finger_miscalibrated":
                    self.miscalibrated.add(s)
                else:
                    self.silent.add(s)
        return time.monotonic()

    # -- the loop --------------------------------------------------------------------------------
    def start(self) -> Dex3HandsEmulator:
        self._thread = threading.Thread(target=self._run, name="dex3-emulator", daemon=True)
        self._thread.start()
        return self

    def close(self) -> None:
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout=2.0)
        self._dds.close()  # a thread that outlived the join finds the entities closed: no take, no write

    def _run(self) -> None:
        last, behind_s = time.monotonic(), 0.0
        next_t = last
        max_steps = int(0.05 / PHYSICS_DT_S)  # after a stall, skip time rather than race to catch up
        while not self._stop.is_set():
            self._apply_commands()
            now = time.monotonic()
            behind_s, last = behind_s + now - last, now
            steps = min(int(behind_s / PHYSICS_DT_S), max_steps)
            behind_s = 0.0 if steps == max_steps else behind_s - steps * PHYSICS_DT_S
            with self._lock:
                for _ in range(steps):
                    for hand in self.hands.values():
                        hand.step(PHYSICS_DT_S)
            self._publish()
            next_t += self.period_s
            delay = next_t - time.monotonic()
            if delay > 0:
                self._stop.wait(delay)
            elif delay < -0.1:
                next_t = time.monotonic()

    def _apply_commands(self) -> None:
        from g1_control.errors import MalformedMessageError
        from g1_control.hardware.unitree.hand_idl import HandCmd_
        from g1_control.hardware.unitree.hand_messages import handcmd_to_finger_command

        for side in self.sides:
            for sample in self._dds.take(f"reader:{side}", 8):  # [] once closed
                if not isinstance(sample, HandCmd_):  # an InvalidSample: a writer went away
                    continue
                try:
                    cmd = handcmd_to_finger_command(sample)
                except (MalformedMessageError, TypeError, ValueError):
                    self.malformed[side] += 1
                    continue
                if not cmd.is_finite():  # a hand's firmware drops what it cannot read as numbers
                    self.malformed[side] += 1
                    continue
                with self._lock:
                    self.hands[side].command = cmd
                self.commands_applied[side] += 1

    def _publish(self) -> None:
        from g1_control.hardware.unitree.hand_messages import finger_state_to_handstate

        for side in self.sides:
            with self._lock:
                if side in self.silent:
                    continue
                frozen = self._frozen_sample.get(side) if side in self.frozen else None
                hand = self.hands[side]
                if frozen is None:
                    noise = self.rng.normal(0.0, 0.002, dex3.NUM_MOTORS)
                    reading = FingerState(q_rad=hand.q.copy(), dq_radps=hand.dq.copy(),
                                          tau_nm=hand.motor_tau + noise, temperature_c=np.full(dex3.NUM_MOTORS, 35.0),
                                          motor_enabled=np.ones(dex3.NUM_MOTORS, dtype=bool) if hand.command is not None
                                          else np.zeros(dex3.NUM_MOTORS, dtype=bool),
                                          power_v=24.0, power_a=0.3 + float(np.abs(hand.motor_tau).sum()) * 0.5
                                          + float(self.rng.normal(0.0, 0.005)))
                    if side in self.miscalibrated:
                        i = dex3.FINGERS.index("middle_1")
                        reading.q_rad[i] = hand.limits.closed_rad[i] + hand.limits.closing_sign[i] * MISCALIBRATION_RAD
                    sample = finger_state_to_handstate(reading, pressure=np.zeros((3, 12)))
                    if side in self.frozen:
                        self._frozen_sample[side] = sample
                else:
                    sample = frozen
            if not self._dds.write(f"writer:{side}", sample):  # closed
                return
            self.states_sent[side] += 1
