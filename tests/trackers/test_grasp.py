"""ForceLimitedGrasp over DDS (loopback, own partition) against the emulated Dex3-1 hands
(g1_control/sim/dex3_hands.py), through Dex3HandLink and GuardedHands as on the robot path.
Judged from the emulator's ground truth (finger angles, the torque the object takes), not from
what the hand reports."""

from __future__ import annotations

import os
import time
import uuid

import numpy as np
import pytest

from g1_control.robot import dex3
from g1_control.safety.hands import GuardedHands
from g1_control.trackers.grasp import ForceLimitedGrasp

LIMIT_NM = 0.5


@pytest.fixture
def hands():
    from g1_control.hardware.hand_link import Dex3HandLink
    from g1_control.sim.dex3_hands import Dex3HandsEmulator

    partition = f"g1hands-{os.getpid()}-{uuid.uuid4().hex[:8]}"
    emulator = Dex3HandsEmulator("lo", 1, partition=partition).start()
    link = Dex3HandLink("lo", 1, partition=partition)
    link.wait_for_state(dex3.SIDES, 5.0)
    time.sleep(0.1)  # the stream's noise has been seen changing (GuardedHands' frozen check)
    yield emulator, link
    link.close()
    emulator.close()


def _run_grasp(link, guarded: GuardedHands, grasp: ForceLimitedGrasp, hold_s: float = 0.5, limit_s: float = 8.0):
    """Act at 100 Hz until the grasp is done, then hold `hold_s` longer; return the seconds to done."""
    t0 = time.monotonic()
    done_at = None
    while time.monotonic() - t0 < limit_s:
        now = time.monotonic()
        guarded.write(grasp.side, grasp.act(link.read(grasp.side), now))
        if grasp.done and done_at is None:
            done_at = now - t0
        if done_at is not None and now - t0 > done_at + hold_s:
            break
        time.sleep(0.01)
    return done_at


def test_a_grasp_closes_on_the_object_and_never_squeezes_past_the_limit(hands):
    emulator, link = hands
    contact = emulator.hold_object("right", closure=0.5)
    guarded = GuardedHands(link)
    grasp = ForceLimitedGrasp("right", torque_limit_nm=LIMIT_NM)
    done_s = _run_grasp(link, guarded, grasp)
    assert done_s is not None and guarded.tripped is None
    truth = emulator.truth("right")
    closing = dex3.hand_limits("right").closing_sign != 0
    assert grasp.touched[closing].all() and not grasp.closed.any()
    # stopped on the object: each closing joint just past its contact angle, pressing on it
    past = dex3.hand_limits("right").closing_sign * (truth.q_rad - contact)
    assert np.all(past[closing] > 0) and np.all(past[closing] < 0.05)
    assert np.all(np.abs(truth.contact_tau_nm[closing]) > 0.6 * LIMIT_NM)
    # never more than the limit, at any physics step of the whole grasp
    assert np.max(truth.max_contact_tau_nm) <= LIMIT_NM
    assert np.max(truth.max_motor_tau_nm) <= LIMIT_NM
    # the left hand was never commanded: its motors produce nothing
    assert emulator.truth("left").last_command is None


def test_with_nothing_in_the_hand_the_fingers_close_fully(hands):
    emulator, link = hands
    guarded = GuardedHands(link)
    grasp = ForceLimitedGrasp("left", torque_limit_nm=LIMIT_NM)
    assert _run_grasp(link, guarded, grasp, hold_s=0.3) is not None
    lim = dex3.hand_limits("left")
    closing = lim.closing_sign != 0
    assert grasp.closed[closing].all() and not grasp.touched.any()
    # inside the safety margin of the closed pose (GuardedHands keeps targets 0.02 rad inside)
    np.testing.assert_allclose(emulator.truth("left").q_rad[closing], lim.closed_rad[closing], atol=0.06)


@pytest.mark.parametrize("fault", ["nan_command", "hand_silent"])
def test_a_fault_while_holding_damps_both_hands(hands, fault):
    emulator, link = hands
    emulator.hold_object("right", closure=0.5)
    guarded = GuardedHands(link)
    grasp = ForceLimitedGrasp("right", torque_limit_nm=LIMIT_NM)
    assert _run_grasp(link, guarded, grasp, hold_s=0.2) is not None
    assert np.max(np.abs(emulator.truth("right").contact_tau_nm)) > 0.6 * LIMIT_NM  # holding
    t_fault = time.monotonic()
    if fault == "nan_command":
        bad = grasp.act(link.read("right"), time.monotonic())
        bad.q_rad[3] = np.nan
        guarded.write("right", bad)
    else:
        emulator.inject("hand_silent", "right")
        while guarded.tripped is None and time.monotonic() - t_fault < 2.0:
            guarded.write("right", grasp.act(link.read("right"), time.monotonic()))
            time.sleep(0.01)
    assert guarded.tripped is not None
    deadline = time.monotonic() + 2.0
    while time.monotonic() < deadline:
        applied = [emulator.truth(s).last_command for s in dex3.SIDES]
        if all(c is not None and c.is_damping for c in applied):
            break
        time.sleep(0.01)
    applied = [emulator.truth(s).last_command for s in dex3.SIDES]
    assert all(c is not None and c.is_damping for c in applied), "the emulated hands never received damping"
    time.sleep(0.3)
    # damped (kp 0): nothing squeezes the object any more
    assert np.max(np.abs(emulator.truth("right").contact_tau_nm)) < 0.05


# -- the controller alone, on hand-made states ------------------------------------------------------

def _state(q, tau, t_s):
    from g1_control.types import FingerState

    return FingerState(q_rad=np.asarray(q, dtype=float), tau_nm=np.asarray(tau, dtype=float), t_s=t_s)


def test_targets_advance_only_on_new_states_and_never_by_more_than_a_step():
    from g1_control.trackers.grasp import MAX_STEP_S

    grasp = ForceLimitedGrasp("right", torque_limit_nm=0.5)  # 1.5 rad/s, kp 3 by default
    q0 = dex3.hand_limits("right").open_rad
    first = grasp.act(_state(q0, np.zeros(7), 1.0), 1.0).q_rad
    again = grasp.act(_state(q0, np.zeros(7), 1.0), 1.5).q_rad  # the same state, half a second later
    np.testing.assert_array_equal(first, again)
    late = grasp.act(_state(q0, np.zeros(7), 2.0), 2.0).q_rad  # a new state after a 1 s stall
    step = np.abs(late - first)
    assert np.max(step) == pytest.approx(1.5 * MAX_STEP_S) and step[0] == 0.0  # thumb_0 holds


def test_a_touching_finger_holds_a_fixed_target_below_the_limit():
    grasp = ForceLimitedGrasp("left", torque_limit_nm=0.5)
    sign = dex3.hand_limits("left").closing_sign
    q = np.full(7, 0.0) + sign * 0.3
    grasp.act(_state(q, np.zeros(7), 1.0), 1.0)
    tau = sign * 0.3  # above half the limit on every closing joint: touched
    held = grasp.act(_state(q, tau, 1.01), 1.01).q_rad
    assert grasp.touched[sign != 0].all() and grasp.done
    np.testing.assert_allclose(held[sign != 0], (q + sign * 0.8 * 0.5 / 3.0)[sign != 0])
    pressed_in = q + sign * 0.05  # the finger presses further into the object
    later = grasp.act(_state(pressed_in, tau, 1.02), 1.02).q_rad
    np.testing.assert_array_equal(later, held)  # the target stays where it was set
    assert np.all(3.0 * sign * (later - pressed_in) <= 0.8 * 0.5 + 1e-12)


def test_a_limit_beyond_the_motors_is_refused():
    with pytest.raises(ValueError, match=r"torque_limit_nm must be in \(0, 1.4\] N m .*; got 2.0"):
        ForceLimitedGrasp("left", torque_limit_nm=2.0)


def test_a_finger_pushed_back_open_after_touching_gives_way_instead_of_squeezing_harder():
    """Held only from the touch angle, a thumb that the other fingers pushed 0.11 rad open squeezed 0.73 N m
    against a 0.5 N m limit (a bottle in the simulated Dex3). Pure: states fed by hand."""
    from g1_control.types import FingerState

    grasp = ForceLimitedGrasp("right", torque_limit_nm=LIMIT_NM)
    sign = grasp.sign
    q = np.zeros(dex3.NUM_MOTORS)
    grasp.act(FingerState(q_rad=q.copy(), t_s=0.0), 0.0)
    touch = np.where(grasp.closing, sign * grasp.touch_fraction * LIMIT_NM, 0.0)  # every closing joint feels it
    q_touch = q + sign * 0.3
    cmd = grasp.act(FingerState(q_rad=q_touch, tau_nm=touch, t_s=0.01), 0.01)
    assert grasp.touched[grasp.closing].all()
    squeeze = sign * cmd.kp * (cmd.q_rad - q_touch)
    assert np.allclose(squeeze[grasp.closing], grasp.hold_fraction * LIMIT_NM)
    pushed = q_touch - sign * 0.11  # pushed back open
    cmd = grasp.act(FingerState(q_rad=pushed, tau_nm=touch, t_s=0.02), 0.02)
    squeeze = sign * cmd.kp * (cmd.q_rad - pushed)
    assert np.all(squeeze[grasp.closing] <= grasp.hold_fraction * LIMIT_NM + 1e-9), squeeze
    # pressed further in, the target stays where it was: the squeeze only falls
    inward = pushed + sign * 0.05
    cmd = grasp.act(FingerState(q_rad=inward, tau_nm=touch, t_s=0.03), 0.03)
    squeeze = sign * cmd.kp * (cmd.q_rad - inward)
    assert np.all(squeeze[grasp.closing] < grasp.hold_fraction * LIMIT_NM - 0.1)
