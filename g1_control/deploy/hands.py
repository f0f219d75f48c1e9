"""The deploy preflight's rows for the Dex3-1 hands (backend.hands: dex3), and their link.

Rows (names in preflight.CHECKS, --override takes them):
- hands_present: a HandState_ arrived from both hands within backend.connect_timeout_s; a silent
  hand is refused by name (not overridable: a hand that cannot be heard cannot be damped);
- hand_state_stream: each hand's HandState_ arrives at >= MIN_HAND_STATE_RATE_HZ over
  deploy.state_window_s, and its contents change (a live hand's current and torque readings
  carry sensor noise; byte-identical samples mean its firmware stopped sampling);
- finger_limits: every finger reads inside its URDF limits (+ deploy.joint_limit_tolerance_rad).
With backend.hands: none the rows are left out of the table (nothing to check).
"""

from __future__ import annotations

import time
from typing import TYPE_CHECKING

import numpy as np

from g1_control.errors import G1ControlError
from g1_control.launch.schema import LaunchFile
from g1_control.robot import dex3

if TYPE_CHECKING:
    from g1_control.deploy.preflight import Preflight
    from g1_control.hardware.hand_link import Dex3HandLink

HAND_CHECKS = ("hands_present", "hand_state_stream", "finger_limits")
"""The rows this module records (described in preflight.CHECKS)."""
MIN_HAND_STATE_RATE_HZ = 50.0
"""Half the 100 Hz the emulator and the host's hand stream run at (assumed: docs/robot_facts.md
gives no rate for the Dex3-1)."""


def open_hand_link(launch: LaunchFile) -> Dex3HandLink:
    """The host side of both hands on the launch file's DDS interface, domain and partition."""
    from g1_control.hardware.hand_link import Dex3HandLink

    b = launch.backend
    if b.type != "unitree_dds":
        raise G1ControlError(f"backend.hands: dex3 needs backend.type unitree_dds (the Dex3-1 hands speak DDS); "
                             f"backend.type is {b.type}")
    return Dex3HandLink(b.interface or "", b.domain, partition=b.partition)


def check_hands(pf: Preflight, launch: LaunchFile, hands: Dex3HandLink | None, open_error: str = "") -> None:
    """Record the three hand rows of `pf` (hands: None when the link could not open)."""
    from g1_control.deploy.preflight import FAIL, PASS

    if launch.backend.hands != "dex3":
        return  # nothing to check: the rows stay out of the table (preflight.OPTIONAL_CHECKS)
    if hands is None:
        pf.record("hands_present", FAIL, f"the hand link did not open: {open_error}", overridable=False)
        pf.not_run(["hand_state_stream", "finger_limits"], "no hand link")
        return
    timeout = launch.backend.connect_timeout_s
    deadline = time.monotonic() + timeout
    for side in hands.sides:
        try:
            hands.wait_for_state((side,), max(0.0, deadline - time.monotonic()))
        except G1ControlError:
            pass
    silent = [s for s in hands.sides if hands.read(s) is None]
    if silent:
        which = f"{' and '.join(silent)} hand{'s' if len(silent) > 1 else ''}"
        pf.record("hands_present", FAIL, f"no HandState_ from the {which} within {timeout:.1f} s "
                  f"on {', '.join(dex3.state_topic(s) for s in silent)} ({hands.describe()}): check that the hand is "
                  "cabled and powered, or set backend.hands: none", overridable=False)
        pf.not_run(["hand_state_stream", "finger_limits"], f"the {which} {'are' if len(silent) > 1 else 'is'} silent")
        return
    pf.record("hands_present", PASS, f"left and right publish on {dex3.state_topic('left')}, "
              f"{dex3.state_topic('right')}")

    window = launch.deploy.state_window_s
    time.sleep(window)
    stats = {s: hands.stats(s, window) for s in hands.sides}
    slow = [f"{s} {st.state_rate_hz:.0f} Hz" for s, st in stats.items() if st.state_rate_hz < MIN_HAND_STATE_RATE_HZ]
    frozen = [s for s, st in stats.items() if st.state_rate_hz * window >= 2 and st.distinct_states <= 1]
    detail = ", ".join(f"{s} {st.state_rate_hz:.0f} Hz" for s, st in stats.items()) + f" over {window:.1f} s"
    problems = []
    if slow:
        problems.append(f"{', '.join(slow)}: need >= {MIN_HAND_STATE_RATE_HZ:.0f} Hz from each hand; check its "
                        "cable and that nothing else loads this host")
    if frozen:
        owner = f"{' and '.join(frozen)} {'hands' if len(frozen) > 1 else 'hand'}'"
        owner += "" if len(frozen) > 1 else "s"
        problems.append(f"the {owner} HandState_ {'are' if len(frozen) > 1 else 'is'} frozen "
                        "(every sample identical, its "
                        "sensor noise included): the hand's firmware stopped sampling; power-cycle the hand")
    if problems:
        pf.record("hand_state_stream", FAIL, f"{detail}; " + "; ".join(problems))
    else:
        pf.record("hand_state_stream", PASS, detail)

    tol = launch.deploy.joint_limit_tolerance_rad
    outside = []
    for side in hands.sides:
        state, lim = hands.read(side), dex3.hand_limits(side)
        assert state is not None  # present, checked above
        for i, name in enumerate(dex3.joint_names(side)):
            q = float(state.q_rad[i])
            if not np.isfinite(q) or q < lim.q_min_rad[i] - tol or q > lim.q_max_rad[i] + tol:
                outside.append(f"{name} {q:.3f} rad (limits [{lim.q_min_rad[i]:.3f}, {lim.q_max_rad[i]:.3f}])")
    if outside:
        pf.record("finger_limits", FAIL, f"{', '.join(outside[:4])}{' ...' if len(outside) > 4 else ''}: a finger "
                  "encoder or its calibration is off; check the hand before moving it")
    else:
        pf.record("finger_limits", PASS, f"all {dex3.NUM_MOTORS * len(hands.sides)} finger joints inside their "
                  f"URDF limits (tolerance {tol:.2f} rad)")
