"""The safety layer's count of IK failures (issue 26: fail-soft IK): up to ik_hold_ticks failures in a
row are held (one `ik_hold` event per run of them, not a trip), one more trips `ik_failure`, a solved
tick ends the run, a failure with nothing to hold trips at once; ik_hold_ticks is a whole number
>= 0, refused otherwise by SafetyConfig and by the launch schema, naming the key."""

from __future__ import annotations

import pytest

from g1_control.errors import LaunchFileError, SafetyConfigError
from g1_control.launch.schema import parse_launch
from g1_control.safety import SafetyConfig, SafetyEventKind, SafetyFilter
from tests.launch.launch_schema_data import launch_data


def test_failures_up_to_the_hold_are_held_and_the_next_trips():
    f = SafetyFilter(SafetyConfig(ik_hold_ticks=2))
    assert f.report_ik_failure("first", 1.0, can_hold=True)
    assert f.report_ik_failure("second", 1.02, can_hold=True)
    assert not f.tripped and f.ik_held_ticks == 2
    assert [(e.kind, e.trips, e.t_s) for e in f.events] == [(SafetyEventKind.IK_HOLD, False, 1.0)]
    assert f.events[0].detail == "the IK found no solution: the last good reference is held (up to 2 tracker ticks): first"
    assert not f.report_ik_failure("third", 1.04, can_hold=True)
    trip = f.trip_event
    assert trip is not None and (trip.kind, trip.t_s, trip.planned) == (SafetyEventKind.IK_FAILURE, 1.04, False)
    assert trip.detail == "the IK found no solution on 3 tracker ticks in a row (safety.ik_hold_ticks 2): third"
    assert f.ik_held_ticks == 2
    assert not f.report_ik_failure("later", 1.06, can_hold=True) and f.trip_event is trip and len(f.events) == 2


def test_a_solved_tick_ends_a_run_of_failures():
    f = SafetyFilter(SafetyConfig(ik_hold_ticks=2))
    for k in range(4):
        assert f.report_ik_failure("a", k, can_hold=True) and f.report_ik_failure("b", k + 0.5, can_hold=True)
        f.report_ik_solved()
    assert not f.tripped and f.ik_held_ticks == 8
    assert [e.t_s for e in f.events] == [0, 1, 2, 3]  # one ik_hold per run


def test_nothing_to_hold_trips_at_once():
    f = SafetyFilter(SafetyConfig(ik_hold_ticks=5))
    assert not f.report_ik_failure("NoSolutionFound: x", 0.0, can_hold=False)
    assert f.trip_event is not None and f.trip_event.kind == SafetyEventKind.IK_FAILURE
    assert f.trip_event.detail == "the IK found no solution before any good reference to hold: NoSolutionFound: x"
    assert f.ik_held_ticks == 0


def test_a_zero_hold_trips_on_the_first_failure():
    f = SafetyFilter(SafetyConfig(ik_hold_ticks=0))
    assert not f.report_ik_failure("x", 0.5, can_hold=True)
    assert f.trip_event is not None and f.trip_event.detail.startswith("the IK found no solution on 1 tracker ticks")
    assert [e.kind for e in f.events] == [SafetyEventKind.IK_FAILURE]


def test_the_default_holds_three_ticks():
    assert SafetyConfig().ik_hold_ticks == 3


@pytest.mark.parametrize("value, text", [
    (1.5, "SafetyConfig.ik_hold_ticks is 1.5; it must be a whole number >= 0 (tracker ticks)"),
    (-1, "SafetyConfig.ik_hold_ticks is -1; it must not be negative"),
    (True, "SafetyConfig.ik_hold_ticks is True; it must be a finite number"),
])
def test_a_hold_that_is_not_a_whole_number_of_ticks_is_refused(value, text):
    with pytest.raises(SafetyConfigError) as info:
        SafetyConfig(ik_hold_ticks=value)
    assert str(info.value) == text


@pytest.mark.parametrize("value, text", [
    (2.5, "<launch>: safety.ik_hold_ticks: expected an integer, got 2.5"),
    (-1, "<launch>: safety: SafetyConfig.ik_hold_ticks is -1; it must not be negative"),
])
def test_the_launch_schema_refuses_a_bad_hold_naming_the_key(value, text):
    with pytest.raises(LaunchFileError) as info:
        parse_launch(launch_data("ik_hold", safety={"ik_hold_ticks": value}))
    assert str(info.value) == text


def test_the_launch_schema_takes_the_hold():
    assert parse_launch(launch_data("ik_hold", safety={"ik_hold_ticks": 0})).safety.ik_hold_ticks == 0
    assert parse_launch(launch_data("ik_hold", safety={"ik_hold_ticks": 10})).safety.ik_hold_ticks == 10
