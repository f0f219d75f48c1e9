"""The deploy preflight's hand rows (backend.hands: dex3) against the emulated Dex3-1 hands on lo:
both present, a missing hand refused by name, a frozen hand's stream refused, a finger outside
its limits refused; left out of the table without hands."""

from __future__ import annotations

import time

import pytest
from deploy_test_helpers import FAST, preflight_only, write_launch

from g1_control.deploy.hands import check_hands, open_hand_link
from g1_control.deploy.preflight import FAIL, NOT_RUN, PASS, Preflight
from g1_control.launch.schema import load_launch
from g1_control.robot import dex3

HANDS = {**FAST, "backend": {**FAST["backend"], "hands": "dex3", "connect_timeout_s": 1.0}}


@pytest.fixture
def emulated_hands(partition):
    from g1_control.sim.dex3_hands import Dex3HandsEmulator

    made = []

    def make(**kwargs):
        emulator = Dex3HandsEmulator("lo", 1, partition=partition, **kwargs).start()
        made.append(emulator)
        return emulator

    yield make
    for emulator in made:
        emulator.close()


def _rows(tmp_path, partition, changes=HANDS):
    launch = load_launch(write_launch(tmp_path, changes))
    launch.backend.partition = partition
    pf = Preflight()
    link = open_hand_link(launch)
    try:
        check_hands(pf, launch, link)
    finally:
        link.close()
    return {name: (pf.results[name].status, pf.results[name].reason) for name in
            ("hands_present", "hand_state_stream", "finger_limits")}, pf


def test_the_deploy_preflight_passes_with_both_hands_streaming(tmp_path, partition, mock_robot, emulated_hands):
    mock_robot().start()
    emulated_hands()
    report, refused, text = preflight_only(write_launch(tmp_path, HANDS), partition)
    assert refused is None, text
    assert "hands_present      PASS        left and right publish on rt/dex3/left/state, rt/dex3/right/state" in text
    assert "finger_limits      PASS        all 14 finger joints inside their URDF limits" in text
    rows = {r["name"]: r for r in report.preflight}
    assert rows["hand_state_stream"]["status"] == PASS


def test_a_missing_hand_is_refused_by_name(tmp_path, partition, emulated_hands):
    emulated_hands(sides=("left",))
    rows, pf = _rows(tmp_path, partition)
    status, reason = rows["hands_present"]
    assert status == FAIL
    assert reason.startswith("no HandState_ from the right hand within 1.0 s on rt/dex3/right/state")
    assert not pf.results["hands_present"].overridable
    assert rows["hand_state_stream"][0] == NOT_RUN and rows["finger_limits"][0] == NOT_RUN
    assert not pf.passed


def test_a_frozen_hand_state_is_refused(tmp_path, partition, emulated_hands):
    emulator = emulated_hands()
    emulator.inject("hand_state_frozen", "left")
    time.sleep(0.05)
    rows, pf = _rows(tmp_path, partition)
    assert rows["hands_present"][0] == PASS
    status, reason = rows["hand_state_stream"]
    assert status == FAIL and not pf.passed
    assert "; the left hand's HandState_ is frozen (every sample identical" in reason
    assert "the right hand" not in reason and "the left and right" not in reason


def test_a_finger_outside_its_limits_is_refused(tmp_path, partition, emulated_hands):
    emulator = emulated_hands()
    lim = dex3.hand_limits("right")
    emulator.inject("finger_miscalibrated", "right")
    time.sleep(0.05)
    rows, _ = _rows(tmp_path, partition)
    status, reason = rows["finger_limits"]
    assert status == FAIL
    assert reason.startswith(f"right_hand_middle_1_joint {lim.q_max_rad[4] + 0.3:.3f} rad (limits [0.000, 1.745])")


def test_a_finger_that_reads_no_number_is_refused(tmp_path, partition, emulated_hands, monkeypatch):
    """A NaN finger reading (a broken encoder or decoding) lies inside no limits: finger_limits fails."""
    monkeypatch.setattr("g1_control.sim.dex3_hands.MISCALIBRATION_RAD", float("nan"))
    emulator = emulated_hands()
    emulator.inject("finger_miscalibrated", "right")
    time.sleep(0.05)
    rows, pf = _rows(tmp_path, partition)
    status, reason = rows["finger_limits"]
    assert status == FAIL and not pf.passed
    assert reason.startswith("right_hand_middle_1_joint nan rad")


def test_without_hands_the_rows_are_left_out(tmp_path):
    launch = load_launch(write_launch(tmp_path, FAST))
    pf = Preflight()
    check_hands(pf, launch, None)
    assert not {"hands_present", "hand_state_stream", "finger_limits"} & set(pf.results)
    assert "hands_present" not in pf.table()
