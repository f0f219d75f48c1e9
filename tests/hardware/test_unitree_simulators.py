"""The host's handling of Unitree's simulators (g1_control/hardware/unitree/simulators.py): what a
profile lets a simulator leave at 0 is filled in, only while it is 0; a wrong non-zero CRC is still
refused; the hint names a simulator's traits only on loopback and only when all of them are 0."""

from __future__ import annotations

import pytest

from g1_control.errors import CrcMismatchError
from g1_control.hardware.links.base import Link
from g1_control.hardware.unitree.messages import LowState
from g1_control.hardware.unitree.simulators import SIMULATORS, RejectedSample, UnsetFields, simulator_hint


class _Dds(Link):
    wire = "dds"

    def send(self, payload: bytes) -> None:
        pass

    def receive(self, timeout_s: float) -> list[bytes]:
        return []


def _payload(*, crc: int | None, tick: int = 0, mode_machine: int = 0) -> bytes:
    """A DDS LowState_ sample with its CRC computed (crc None), or with `crc` written over it."""
    data = LowState(tick=tick, mode_machine=mode_machine).to_dds()
    return data if crc is None else data[:-4] + crc.to_bytes(4, "little")


def test_unset_fields_are_filled_and_counted():
    filler, link = UnsetFields(SIMULATORS["unitree_mujoco"], mode_machine=5), _Dds("host")
    ticks = [filler.decode(link, _payload(crc=0)).tick for _ in range(3)]
    assert ticks == [1, 2, 3]  # the host's count: advances with every sample
    msg = filler.decode(link, _payload(crc=0))
    assert msg.mode_machine == 5 and msg.crc == 0
    assert filler.filled == {"crc", "tick", "mode_machine"}
    assert filler.describe_filled() == "crc 0 accepted unchecked, tick 0 counted by the host, mode_machine 0 read as 5"


def test_fields_a_simulator_does_fill_are_taken_and_checked_as_a_robot_s():
    filler, link = UnsetFields(SIMULATORS["unitree_mujoco"], mode_machine=5), _Dds("host")
    msg = filler.decode(link, _payload(crc=None, tick=1234, mode_machine=6))  # the C++ simulate fills tick
    assert (msg.tick, msg.mode_machine) == (1234, 6) and filler.filled == set()
    with pytest.raises(CrcMismatchError):
        filler.decode(link, _payload(crc=0xDEADBEEF))  # wrong and not 0: corrupted, refused


def test_the_hint_needs_loopback_and_every_trait_at_zero():
    zero = RejectedSample(crc=0, tick=0, mode_machine=0)
    assert "crc, tick and mode_machine all 0" in simulator_hint(zero, loopback=True)
    assert simulator_hint(zero, loopback=False) == ""
    assert simulator_hint(RejectedSample(crc=0, tick=7, mode_machine=0), loopback=True) == ""
    assert "tick and mode_machine all 0" in simulator_hint(None, tick=0, mode_machine=0, loopback=True)
    assert simulator_hint(None, tick=0, mode_machine=5, loopback=True) == ""
