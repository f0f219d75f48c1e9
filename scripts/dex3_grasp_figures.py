"""Figures of the Dex3-1 hands over DDS (lo, own partition) against the emulated hands, from the
emulator's ground truth: force-limited grasps over a grid of object sizes and torque limits (peak
and held squeeze against the limit, time to close), and the time from a fault to damping applied
in the hand. Also the cost of encoding/decoding the messages.

    PYTHONPATH=. python3 scripts/dex3_grasp_figures.py
"""

from __future__ import annotations

import os
import time
import uuid

import numpy as np

from g1_control.hardware.hand_link import Dex3HandLink
from g1_control.hardware.unitree.hand_idl import HandState_
from g1_control.hardware.unitree.hand_messages import finger_command_to_handcmd, finger_state_to_handstate
from g1_control.robot import dex3
from g1_control.safety.hands import GuardedHands
from g1_control.sim.dex3_hands import Dex3HandsEmulator
from g1_control.trackers.grasp import ForceLimitedGrasp
from g1_control.types import FingerCommand, FingerState


def open_hand(emulator, link, side):
    """Open the hand (stiff, at the open pose) with no object in it, then damp."""
    emulator.release_object(side)
    link.write(side, FingerCommand(q_rad=dex3.hand_limits(side).open_rad, kp=np.full(7, 2.0), kd=np.full(7, 0.05)))
    time.sleep(1.0)
    link.damp((side,))
    time.sleep(0.1)


def grasp_once(emulator, link, side, closure, limit):
    open_hand(emulator, link, side)
    emulator.hold_object(side, closure)
    guarded = GuardedHands(link)
    grasp = ForceLimitedGrasp(side, torque_limit_nm=limit)
    t0 = time.monotonic()
    done = None
    while time.monotonic() - t0 < 8.0:
        now = time.monotonic()
        guarded.write(side, grasp.act(link.read(side), now))
        if done is None and grasp.done:
            done = now - t0
        if done is not None and now - t0 > done + 0.5:
            break
        time.sleep(0.01)
    truth = emulator.truth(side)
    closing = dex3.hand_limits(side).closing_sign != 0
    held = np.abs(truth.contact_tau_nm[closing])
    return done, float(np.max(truth.max_contact_tau_nm)) / limit, float(held.min()) / limit, float(held.max()) / limit, \
        guarded.tripped


def fault_to_damping(emulator, link, side):
    """Seconds from a NaN command to damping applied in both emulated hands."""
    guarded = GuardedHands(link)
    grasp = ForceLimitedGrasp(side)
    for _ in range(20):
        guarded.write(side, grasp.act(link.read(side), time.monotonic()))
        time.sleep(0.01)
    bad = grasp.act(link.read(side), time.monotonic())
    bad.q_rad[0] = np.nan
    t0 = time.monotonic()
    guarded.write(side, bad)
    while time.monotonic() - t0 < 2.0:
        cmds = [emulator.truth(s).last_command for s in dex3.SIDES]
        if all(c is not None and c.is_damping for c in cmds):
            return time.monotonic() - t0
        time.sleep(0.0005)
    return float("nan")


def main() -> None:
    partition = f"figures-{os.getpid()}-{uuid.uuid4().hex[:6]}"
    emulator = Dex3HandsEmulator("lo", 1, partition=partition).start()
    link = Dex3HandLink("lo", 1, partition=partition)
    link.wait_for_state(dex3.SIDES, 5.0)
    time.sleep(0.2)
    rows = []
    for closure in (0.2, 0.5, 0.8):
        for limit in (0.3, 0.5, 1.0):
            for side in dex3.SIDES:
                emulator.inject("clear")
                rows.append((side, closure, limit, *grasp_once(emulator, link, side, closure, limit)))
    print("side   closure limit  done_s  peak/limit  held min/limit  held max/limit  tripped")
    for side, closure, limit, done, peak, hmin, hmax, tripped in rows:
        print(f"{side:<6} {closure:<7} {limit:<6} {done if done is not None else float('nan'):6.2f}  {peak:10.2f}  "
              f"{hmin:14.2f}  {hmax:14.2f}  {tripped or '-'}")
    peaks = np.array([r[4] for r in rows])
    print(f"grasps {len(rows)}, closed {sum(r[3] is not None for r in rows)}, peak/limit max {peaks.max():.2f}, "
          f"mean {peaks.mean():.2f}")
    latencies = []
    for _ in range(10):
        open_hand(emulator, link, "right")
        latencies.append(fault_to_damping(emulator, link, "right"))
    print(f"NaN command -> damping applied in both emulated hands: p50 {np.median(latencies) * 1e3:.1f} ms, "
          f"max {np.max(latencies) * 1e3:.1f} ms over {len(latencies)}")
    link.close()
    emulator.close()

    cmd = FingerCommand(q_rad=np.linspace(0, 1, 7), kp=np.full(7, 3.0), kd=np.full(7, 0.05))
    state = finger_state_to_handstate(FingerState(q_rad=np.linspace(0, 1, 7)), pressure=np.zeros((3, 12)))
    data = state.serialize()
    n = 500
    t0 = time.perf_counter()
    for _ in range(n):
        finger_command_to_handcmd(cmd).serialize()
    t1 = time.perf_counter()
    for _ in range(n):
        HandState_.deserialize(data)
    t2 = time.perf_counter()
    print(f"encode FingerCommand -> HandCmd_ bytes {(t1 - t0) / n * 1e6:.0f} us; decode HandState_ "
          f"({len(data)} bytes) {(t2 - t1) / n * 1e6:.0f} us")


if __name__ == "__main__":
    main()
