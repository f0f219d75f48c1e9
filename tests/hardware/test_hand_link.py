"""Dex3HandLink over DDS (loopback, own partition) against the emulated Dex3-1 hands: what a hand
last hears when the link closes."""

from __future__ import annotations

import os
import time
import uuid

import numpy as np

from g1_control.robot import dex3
from g1_control.types import FingerCommand


def test_close_leaves_every_commanded_hand_damping():
    """close() streams damping (kp 0, kd > 0) to each hand it commanded before the stream stops: the last
    command the hand applied is damping, not the stiff grip it was holding."""
    from g1_control.hardware.hand_link import Dex3HandLink
    from g1_control.sim.dex3_hands import Dex3HandsEmulator

    partition = f"g1hands-{os.getpid()}-{uuid.uuid4().hex[:8]}"
    emulator = Dex3HandsEmulator("lo", 1, partition=partition).start()
    link = Dex3HandLink("lo", 1, partition=partition)
    try:
        link.wait_for_state(dex3.SIDES, 5.0)
        grip = FingerCommand(q_rad=dex3.hand_limits("left").closed_rad.copy(), kp=np.full(7, 2.0), kd=np.full(7, 0.05))
        link.write("left", grip)
        deadline = time.monotonic() + 3.0
        while time.monotonic() < deadline and emulator.hands["left"].command is None:
            time.sleep(0.01)
        assert np.all(emulator.hands["left"].command.kp == 2.0), "the grip reached the hand"
        link.close()
        assert emulator.hands["left"].command.is_damping
        assert emulator.hands["right"].command is None, "a hand that was never commanded is left alone"
    finally:
        link.close()
        emulator.close()
