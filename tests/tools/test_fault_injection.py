"""Every fault ends in damping frames on the wire, over real DDS on loopback, within one 50 Hz tick
of the safety layer tripping. Detection budgets are loose (shared host): stale-state faults need
their 50 ms threshold plus a tick, lost input its 1 s timeout, overruns five late ticks."""

from __future__ import annotations

import warnings

import pytest

from g1_control.tools.fault_suite import ALL_FAULTS, format_table, run_suite

pytestmark = pytest.mark.timing

EXPECTED_TRIP = {
    "state_stops": ("stale_state", 250), "state_frozen": ("stale_state", 300), "crc_corrupted": ("crc_burst", 200),
    "tilt": ("tilt", 200), "overspeed": ("joint_overspeed", 200), "over_temperature": ("over_temperature", 200),
    "nan_policy_output": ("nonfinite_command", 200), "joystick_lost": ("input_lost", 1500),
    "deadline_overruns": ("deadline_overruns", 800), "SIGINT": ("estop", 200), "SIGTERM": ("estop", 200),
}


@pytest.fixture(scope="module")
def results():
    out = run_suite(ALL_FAULTS, progress=False)
    print("\n" + format_table(out))
    return {r.fault: r for r in out}


TIMING_ATTEMPTS = 3
"""Runs of a fault whose trip was right but late (this shared host slows 5-10x for tens of ms at a
time): a late trial is run again, a warning each; a fault late every time, or tripped as the wrong
kind, fails."""


def _in_time(r, detect_budget_ms: float) -> bool:
    return 0 <= r.detect_ms < detect_budget_ms and 0 <= r.to_wire_ms < 40


@pytest.mark.parametrize("fault", ALL_FAULTS)
def test_fault_is_detected_and_damping_reaches_the_robot(results, fault):
    r = results[fault]
    kind, detect_budget_ms = EXPECTED_TRIP[fault]
    for attempt in range(2, TIMING_ATTEMPTS + 1):
        if r.tripped_as != kind or _in_time(r, detect_budget_ms):
            break
        warnings.warn(f"{fault}: late on this host (attempt {attempt - 1} of {TIMING_ATTEMPTS}), run again: {r}",
                      stacklevel=1)
        r = run_suite([fault], progress=False)[0]
    assert r.tripped_as == kind, r
    assert 0 <= r.detect_ms < detect_budget_ms, r
    # The damping frame reaches the robot within one 50 Hz tick (20 ms) of the trip; allow a
    # second tick for scheduling noise on a loaded host.
    assert 0 <= r.to_wire_ms < 40, r


def test_the_suite_ran_a_trial_of_every_fault_and_each_has_an_expected_trip(results):
    """The suite's own results, not its list: a fault it skipped or ran twice, or one without an
    expected trip here, fails."""
    assert sorted(results) == sorted(ALL_FAULTS) == sorted(EXPECTED_TRIP)
    assert len(set(ALL_FAULTS)) == len(ALL_FAULTS) >= 10
    assert all(results[f].fault == f for f in ALL_FAULTS)
