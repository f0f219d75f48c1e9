"""The emulated Dex3-1 hands: the finger model's motor law, and the emulator over DDS (HandCmd_
applied, HandState_ published, faults)."""

from __future__ import annotations

import os
import time
import uuid

import numpy as np
import pytest

from g1_control.robot import dex3
from g1_control.sim.dex3_hands import EmulatedHand
from g1_control.types import FingerCommand


def _settle(hand: EmulatedHand, seconds: float = 1.0) -> None:
    for _ in range(int(seconds / 0.0005)):
        hand.step(0.0005)


def test_no_command_no_torque():
    hand = EmulatedHand("left")
    q0 = hand.q.copy()
    _settle(hand, 0.2)
    assert np.all(hand.motor_tau == 0.0) and np.array_equal(hand.q, q0)


def test_the_motor_law_brings_each_finger_to_its_target():
    hand = EmulatedHand("right")
    lim = hand.limits
    target = (lim.open_rad + lim.closed_rad) / 2
    hand.command = FingerCommand(q_rad=target, kp=np.full(7, 2.0), kd=np.full(7, 0.05))
    _settle(hand)
    np.testing.assert_allclose(hand.q, target, atol=1e-3)


def test_disabled_motors_and_effort_limits():
    hand = EmulatedHand("left")
    enable = np.ones(7, dtype=bool)
    enable[2] = False
    hand.command = FingerCommand(q_rad=hand.limits.closed_rad, kp=np.full(7, 100.0), kd=np.zeros(7), enable=enable)
    hand.step(0.0005)
    assert hand.motor_tau[2] == 0.0
    np.testing.assert_allclose(np.abs(hand.motor_tau[3:]), hand.limits.effort_nm[3:])  # clipped to 1.4 N m
    _settle(hand)
    closing = hand.limits.closing_sign != 0
    closing[2] = False
    # hard stops at the URDF limits
    np.testing.assert_allclose(hand.q[closing], hand.limits.closed_rad[closing], atol=1e-9)


@pytest.fixture
def rig():
    from g1_control.hardware.hand_link import Dex3HandLink
    from g1_control.sim.dex3_hands import Dex3HandsEmulator

    partition = f"g1hands-{os.getpid()}-{uuid.uuid4().hex[:8]}"
    emulator = Dex3HandsEmulator("lo", 1, partition=partition).start()
    link = Dex3HandLink("lo", 1, partition=partition)
    link.wait_for_state(dex3.SIDES, 5.0)
    yield emulator, link
    link.close()
    emulator.close()


def test_commands_over_dds_move_the_emulated_fingers(rig):
    emulator, link = rig
    lim = dex3.hand_limits("left")
    target = (lim.open_rad + lim.closed_rad) / 2
    link.write("left", FingerCommand(q_rad=target, kp=np.full(7, 2.0), kd=np.full(7, 0.05)))
    time.sleep(1.0)
    np.testing.assert_allclose(emulator.truth("left").q_rad, target, atol=0.01)  # ground truth
    np.testing.assert_allclose(link.read("left").q_rad, target, atol=0.01)  # and what the hand reports
    assert emulator.truth("right").last_command is None
    stats = link.stats("left")
    assert stats.state_rate_hz > 50 and stats.commands_sent > 50


def test_a_non_finite_command_is_dropped_by_the_hand(rig):
    emulator, link = rig
    bad = FingerCommand(kp=np.full(7, 2.0), kd=np.full(7, 0.05))
    bad.q_rad[0] = np.inf
    link.write("right", bad)
    time.sleep(0.3)
    assert emulator.truth("right").last_command is None and emulator.malformed["right"] > 0


def test_faults_silence_or_freeze_the_stream(rig):
    emulator, link = rig
    emulator.inject("hand_state_frozen", "left")
    emulator.inject("hand_silent", "right")
    time.sleep(0.1)
    changed_left, received_right = link.last_change_s("left"), link.stats("right").states_received
    time.sleep(0.4)
    left = link.stats("left", window_s=0.4)
    assert left.state_rate_hz > 50 and left.distinct_states == 0 and link.last_change_s("left") == changed_left
    assert link.stats("right").states_received == received_right
    emulator.inject("clear")
    time.sleep(0.3)
    assert link.last_change_s("left") > changed_left and link.stats("right").states_received > received_right
    with pytest.raises(ValueError, match="unknown hand fault 'melt'"):
        emulator.inject("melt")
