"""Unitree's own simulators as sim2sim targets: what they leave unset in LowState_, and how the
host fills it in (backend.simulator in a launch file; loopback only).

Unitree's MuJoCo simulator (unitree_mujoco, `simulate_python`) publishes LowState_ with crc,
tick and mode_machine all 0, at its physics rate (SIMULATE_DT 0.005: 200 Hz), computes the PD
torque only when a LowCmd_ arrives and holds it in between, and runs no motion service. Its C++
`simulate` fills tick (ms) and mode_machine (5). A robot fills all three; the host refuses a
stream without them (bad CRC, no G1 variant, a frozen tick), which is right for a robot and
wrong for these simulators. With a profile the host accepts exactly what the profile names as
unset, and only while it is unset (a simulator that does fill a field is checked as a robot is):

  crc           a LowState_ whose crc is 0 is taken without a CRC check (a wrong non-zero CRC
                is still dropped)
  tick          a tick of 0 is replaced by the host's count of samples received (the safety
                layer's frozen/backwards tick checks then watch that count)
  mode_machine  0 is replaced by the launch file's expected variant's mode_machine

    filler = UnsetFields(SIMULATORS["unitree_mujoco"], mode_machine=5)
    msg = filler.decode(link, payload)       # CrcMismatchError for a wrong non-zero CRC
    filler.filled                            # the fields it had to fill so far
"""

from __future__ import annotations

from dataclasses import dataclass, field

from g1_control.errors import CrcMismatchError
from g1_control.hardware.unitree.messages import LowState

UNSET_FIELDS = ("crc", "tick", "mode_machine")


@dataclass(frozen=True)
class SimulatorProfile:
    name: str
    describe: str
    unset: tuple[str, ...]
    """LowState_ fields the simulator may leave at 0 (of UNSET_FIELDS)."""
    state_rate_hz: float
    """The rate it publishes LowState_ at (its physics rate)."""
    motion_service: bool
    """Whether it runs a motion service to release (none: nothing is released)."""


SIMULATORS: dict[str, SimulatorProfile] = {
    "unitree_mujoco": SimulatorProfile(
        "unitree_mujoco", "Unitree's MuJoCo simulator (unitree_mujoco: simulate_python, or the C++ simulate)",
        unset=UNSET_FIELDS, state_rate_hz=200.0, motion_service=False),
}


def min_state_rate_hz(profile: SimulatorProfile | None, robot_min_hz: float) -> float:
    """The preflight's lowest acceptable LowState_ rate: a robot's, or 80 % of the simulator's own."""
    return robot_min_hz if profile is None else min(robot_min_hz, 0.8 * profile.state_rate_hz)


@dataclass
class UnsetFields:
    """Host side: decodes LowState_ samples, filling what `profile` lets a simulator leave unset."""

    profile: SimulatorProfile
    mode_machine: int
    """What a mode_machine of 0 becomes (the launch file's expected variant)."""
    filled: set[str] = field(default_factory=set)
    samples: int = 0

    def decode(self, link, payload: bytes) -> LowState:
        try:
            msg = link.decode_state(payload)
        except CrcMismatchError:
            if "crc" not in self.profile.unset:
                raise
            msg = link.decode_state(payload, verify=False)
            if int(msg.crc) != 0:
                raise
            self.filled.add("crc")
        self.samples += 1
        if "tick" in self.profile.unset and int(msg.tick) == 0:
            msg.tick = self.samples & 0xFFFFFFFF
            self.filled.add("tick")
        if "mode_machine" in self.profile.unset and int(msg.mode_machine) == 0:
            msg.mode_machine = self.mode_machine
            self.filled.add("mode_machine")
        return msg

    def describe_filled(self) -> str:
        """'crc 0 accepted, tick 0 counted by the host, mode_machine 0 read as 5', or ''."""
        parts = {"crc": "crc 0 accepted unchecked", "tick": "tick 0 counted by the host",
                 "mode_machine": f"mode_machine 0 read as {self.mode_machine}"}
        return ", ".join(parts[f] for f in UNSET_FIELDS if f in self.filled)


@dataclass(frozen=True)
class RejectedSample:
    """What a LowState_ dropped for its CRC carried (decoded unchecked), for the preflight's hints."""

    crc: int
    tick: int
    mode_machine: int


def simulator_hint(sample: RejectedSample | None, *, tick: int | None = None, mode_machine: int | None = None,
                   loopback: bool) -> str:
    """A hint when a stream on loopback looks like one of Unitree's simulators ('' otherwise):
    `sample` a LowState_ dropped for its CRC, or tick/mode_machine of the accepted ones."""
    if not loopback:
        return ""
    fields = ((("crc", sample.crc), ("tick", sample.tick), ("mode_machine", sample.mode_machine)) if sample is not None
              else (("tick", tick), ("mode_machine", mode_machine)))
    if any(v != 0 for _, v in fields):
        return ""
    names = ", ".join(n for n, _ in fields[:-1]) + " and " + fields[-1][0]
    return (f"; hint: the LowState_ on loopback carries {names} all 0, as Unitree's MuJoCo simulator "
            "(unitree_mujoco) publishes it: not a robot. To run against it, set backend.simulator: unitree_mujoco "
            "(loopback only; see g1_control/hardware/unitree/simulators.py)")


__all__ = ["SIMULATORS", "UNSET_FIELDS", "RejectedSample", "SimulatorProfile", "UnsetFields", "min_state_rate_hz",
           "simulator_hint"]
