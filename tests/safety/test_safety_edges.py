"""The safety filter and its config at their edges (mutation-run survivors, issue 16): every threshold
is strict or inclusive exactly as documented, the constructor's callback and the accepted
mode_machine take effect, single bad CRCs count, the input watchdog measures from the last input,
each trip's detail in full, clamps to limits that float32 carries exactly, the enable mask handed on."""

from __future__ import annotations

import logging
import math

import numpy as np
import pytest

from g1_control.errors import SafetyConfigError
from g1_control.robot import g1
from g1_control.rotations import tilt_rad
from g1_control.safety import SafetyConfig, SafetyEvent, SafetyEventKind, SafetyFilter
from g1_control.types import Command
from tests.safety.safety_test_helpers import command as _cmd
from tests.safety.safety_test_helpers import state as _state


def _tripped(f: SafetyFilter, kind: SafetyEventKind, detail: str) -> None:
    assert f.trip_event is not None, "expected a trip"
    assert (f.trip_event.kind, f.trip_event.detail) == (kind, detail)


# -- config ---------------------------------------------------------------------------------------------
def test_config_bounds_that_are_inclusive():
    """A burst of one is one event; a robot may damp the moment it stops (both watchdogs at 0.5 s)."""
    crc = SafetyFilter(SafetyConfig(crc_burst_count=1, overrun_burst_count=1))
    assert crc.report_crc_errors(1, 0.0) is False and crc.trip_event.kind == SafetyEventKind.CRC_BURST
    overrun = SafetyFilter(SafetyConfig(crc_burst_count=1, overrun_burst_count=1))
    assert overrun.report_deadline(True, 0.0) is False and overrun.trip_event.kind == SafetyEventKind.DEADLINE_OVERRUNS
    f = SafetyFilter(SafetyConfig(input_zero_velocity_s=0.5, input_lost_s=0.5))
    f.vet_input(Command(vx_mps=0.4), 0.0)
    assert f.vet_input(None, 0.5).vx_mps == 0.4 and f.check(_state(0.5), 0.5), "0.5 s late is not yet late"
    assert f.vet_input(None, 0.52).vx_mps == 0.0
    assert not f.check(_state(0.52), 0.52) and f.trip_event.kind == SafetyEventKind.INPUT_LOST


def test_a_boolean_is_no_threshold():
    with pytest.raises(SafetyConfigError, match="SafetyConfig.stale_state_s is True; it must be a finite number"):
        SafetyConfig(stale_state_s=True)
    with pytest.raises(SafetyConfigError, match="SafetyConfig.max_kp is '5'; it must be a finite number"):
        SafetyConfig(max_kp="5")


def test_an_event_that_does_not_trip_says_so():
    assert str(SafetyEvent(1.0, SafetyEventKind.INPUT_STALE, "late", trips=False)) == "[1.000 s] input_stale: late"


# -- clamps ---------------------------------------------------------------------------------------------
def test_limits_float32_carries_exactly_are_clamped_to_exactly():
    cmd = _cmd()
    cmd.dq_radps[:] = 100.0
    cmd.dq_radps[1] = -100.0
    cmd.tau_nm[0] = 1000.0
    out = SafetyFilter().filter(cmd, _state(), 0.0)
    assert out.dq_radps[0] == 32.0 and out.dq_radps[1] == -20.0 and out.tau_nm[0] == 88.0


def test_lower_position_targets_stay_inside_after_float32_rounding():
    cmd = _cmd()
    cmd.q_rad[:] = -100.0
    out = SafetyFilter().filter(cmd, _state(), 0.0)
    assert np.all(out.q_rad >= g1.Q_MIN_RAD)
    assert np.all(out.q_rad.astype(np.float32).astype(np.float64) >= g1.Q_MIN_RAD)
    assert np.all(out.q_rad - g1.Q_MIN_RAD < 1e-6)


def test_the_position_margin_keeps_targets_inside_both_limits():
    f = SafetyFilter(SafetyConfig(position_margin_rad=0.1))
    low, high = _cmd(), _cmd()
    low.q_rad[:], high.q_rad[:] = -100.0, 100.0
    lo, hi = f.filter(low, _state(), 0.0).q_rad, f.filter(high, _state(0.002), 0.002).q_rad
    np.testing.assert_allclose(lo, g1.Q_MIN_RAD + 0.1, atol=1e-6)
    np.testing.assert_allclose(hi, g1.Q_MAX_RAD - 0.1, atol=1e-6)


def test_every_clamped_command_is_counted():
    f = SafetyFilter()
    for i in range(3):
        cmd = _cmd()
        cmd.kp[0] = -1.0
        f.filter(cmd, _state(i * 0.002), i * 0.002)
    assert f.clamps.commands == 3 and f.clamps.per_joint["kp"][0] == 3


def test_the_enable_mask_is_handed_on_as_a_bool_copy():
    enable = np.ones(29, dtype=np.int64)
    enable[[3, 7]] = 0
    cmd = _cmd(enable=enable)
    out = SafetyFilter().filter(cmd, _state(), 0.0)
    assert out.enable.dtype == bool and out.enable.shape == (29,)
    assert not out.enable[3] and not out.enable[7] and out.enable.sum() == 27
    assert out.enable is not cmd.enable


# -- non-finite commands ----------------------------------------------------------------------------------
@pytest.mark.parametrize(("fields", "detail"), [
    (("tau_nm",), "MotorCommand.tau_nm contains NaN or inf"),
    (("q_rad", "kd"), "MotorCommand.q_rad, kd contain NaN or inf"),
])
def test_a_nonfinite_command_names_its_fields(fields, detail):
    cmd = _cmd()
    for name in fields:
        getattr(cmd, name)[2] = np.nan
    f = SafetyFilter()
    f.filter(cmd, _state(), 0.0)
    _tripped(f, SafetyEventKind.NONFINITE_COMMAND, detail)


@pytest.mark.filterwarnings("ignore:overflow encountered:RuntimeWarning")
def test_a_command_whose_sum_overflows_trips_too():
    cmd = _cmd()
    cmd.tau_nm[:2] = 1e308  # each finite; their sum is not: the safe side
    f = SafetyFilter()
    f.filter(cmd, _state(), 0.0)
    _tripped(f, SafetyEventKind.NONFINITE_COMMAND, "MotorCommand.values contains NaN or inf")


# -- state checks ---------------------------------------------------------------------------------------
def test_a_nonfinite_state_names_the_joint_or_the_index():
    f = SafetyFilter()
    state = _state()
    state.q_rad[1] = np.nan
    f.check(state, 0.0)
    _tripped(f, SafetyEventKind.NONFINITE_STATE, "RobotState.q_rad contains NaN or inf (left_hip_roll_joint = nan)")
    g = SafetyFilter()
    state = _state()
    state.imu_gyro_radps = np.array([0.0, -np.inf, 0.0])
    g.check(state, 0.0)
    _tripped(g, SafetyEventKind.NONFINITE_STATE, "RobotState.imu_gyro_radps contains NaN or inf ([1] = -inf)")


@pytest.mark.parametrize(("t_s", "now_s"), [(math.nan, 0.0), (0.0, math.inf)])
def test_a_nonfinite_time_trips(t_s, now_s):
    f = SafetyFilter()
    assert not f.check(_state(tick=0, t_s=t_s), now_s)
    _tripped(f, SafetyEventKind.NONFINITE_STATE, f"time is not finite (state {t_s}, now {now_s})")
    assert f.trip_event.t_s == now_s or math.isnan(now_s)


def test_the_accepted_mode_machine_is_required_from_the_first_state():
    f = SafetyFilter()
    f.expect_mode_machine(6)
    assert not f.check(_state(mode_machine=5), 0.0)
    _tripped(f, SafetyEventKind.MODE_MACHINE_CHANGED, "RobotState.mode_machine changed from 6 to 5 (another DoF "
                                                      "variant, or a second publisher)")


def test_joints_exactly_at_their_range_pass_and_the_lower_margin_counts():
    f = SafetyFilter(SafetyConfig(state_limit_margin_rad=0.0))
    at_min, at_max = _state(), _state(0.002)
    at_min.q_rad[:] = g1.Q_MIN_RAD
    at_max.q_rad[:] = g1.Q_MAX_RAD
    assert f.check(at_min, 0.0) and f.check(at_max, 0.002)
    knee = g1.JOINT_INDEX["left_knee_joint"]
    near = _state()
    near.q_rad[knee] = g1.Q_MIN_RAD[knee] - 0.2
    assert SafetyFilter().check(near, 0.0), "0.2 rad below the limit is within the default 0.25 rad margin"


def test_a_quaternion_norm_error_exactly_at_the_limit_passes():
    f = SafetyFilter(SafetyConfig(max_quat_norm_error=0.5))
    assert f.check(_state(imu_quat_wxyz=np.array([1.5, 0.0, 0.0, 0.0])), 0.0)


def test_tick_steps_of_half_the_u32_range_count_as_going_back():
    f = SafetyFilter()
    assert f.check(_state(0.0, tick=0), 0.0)
    assert f.check(_state(0.01, tick=2**31 - 1), 0.01), "just under half the range: forward"
    g = SafetyFilter()
    assert g.check(_state(0.0, tick=0), 0.0)
    assert not g.check(_state(0.01, tick=2**31), 0.01)
    _tripped(g, SafetyEventKind.STATE_OUT_OF_RANGE, "RobotState.tick went back from 0 to 2147483648 (a second "
                                                    "publisher, or the robot restarted)")


def test_a_state_exactly_stale_state_s_old_passes_and_the_limit_is_in_words():
    assert SafetyFilter().check(_state(0.0), 0.05)
    f = SafetyFilter(SafetyConfig(stale_state_s=1.0))
    assert not f.check(_state(0.0), 1.5)
    _tripped(f, SafetyEventKind.STALE_STATE, "newest state is 1500.0 ms old (limit 1000 ms)")


def test_a_tick_frozen_exactly_stale_state_s_passes_and_the_limit_is_in_words():
    f = SafetyFilter()
    assert f.check(_state(0.0, tick=4), 0.0)
    assert f.check(_state(0.05, tick=4), 0.05)
    g = SafetyFilter(SafetyConfig(stale_state_s=1.0))
    assert g.check(_state(0.0, tick=4), 0.0)
    assert not g.check(_state(1.5, tick=4), 1.5)
    _tripped(g, SafetyEventKind.STALE_STATE, "state tick frozen at 4 for 1500.0 ms (limit 1000 ms)")


def test_a_tilt_exactly_at_the_limit_passes():
    quat = np.array([math.cos(0.3), math.sin(0.3), 0.0, 0.0])
    assert SafetyFilter(SafetyConfig(max_tilt_rad=tilt_rad(quat))).check(_state(imu_quat_wxyz=quat), 0.0)


def test_a_motor_exactly_at_the_temperature_limit_passes():
    state = _state()
    state.motor_temperature_c[4] = 90.0
    assert SafetyFilter().check(state, 0.0)


# -- CRC bursts -----------------------------------------------------------------------------------------
def test_single_bad_crcs_count_from_the_first_report():
    f = SafetyFilter(SafetyConfig(crc_burst_count=5, crc_burst_window_s=1.0))
    for i in range(1, 5):
        assert f.report_crc_errors(i, now_s=i * 0.01)
    assert not f.report_crc_errors(5, now_s=0.05)
    _tripped(f, SafetyEventKind.CRC_BURST, "5 bad-CRC states within 1000 ms (5 in total)")
    g = SafetyFilter(SafetyConfig(crc_burst_count=5, crc_burst_window_s=0.1))
    assert not g.report_crc_errors(5, now_s=2.0), "five at the first report: a burst"
    _tripped(g, SafetyEventKind.CRC_BURST, "5 bad-CRC states within 100 ms (5 in total)")


# -- bursts of deadline overruns -------------------------------------------------------------------------------
def test_a_burst_is_measured_from_its_oldest_event_and_its_window_is_inclusive():
    f = SafetyFilter(SafetyConfig(overrun_burst_count=5, overrun_window_s=0.25))
    for t in (0.0, 0.0625, 0.125, 0.1875):
        assert f.report_deadline(True, t)
    assert not f.report_deadline(True, 0.25), "five within exactly 0.25 s"
    _tripped(f, SafetyEventKind.DEADLINE_OVERRUNS, "5 deadline overruns within 0.2 s")
    g = SafetyFilter(SafetyConfig(overrun_burst_count=5, overrun_window_s=0.1))
    for t in (0.0, 0.15, 0.16, 0.17):
        assert g.report_deadline(True, t)
    assert g.report_deadline(True, 0.18), "the oldest of the five is 0.18 s old"


# -- operator input ---------------------------------------------------------------------------------------
def test_the_input_watchdogs_measure_from_the_last_input():
    f = SafetyFilter(SafetyConfig(input_zero_velocity_s=0.25, input_lost_s=1.0))
    walk = Command(vx_mps=0.5, vy_mps=0.3, wz_radps=0.2, buttons=frozenset({"run"}))
    f.vet_input(walk, 10.0)
    assert f.vet_input(None, 10.125).vx_mps == 0.5
    assert f.vet_input(None, 10.25).vx_mps == 0.5, "exactly input_zero_velocity_s late: still held"
    assert f.vet_input(None, 10.375).vx_mps == 0.0
    assert f.check(_state(10.5), 10.5)
    assert f.check(_state(11.0), 11.0), "exactly input_lost_s late: not lost yet"
    assert not f.check(_state(11.25), 11.25)
    _tripped(f, SafetyEventKind.INPUT_LOST, "no operator input for 1.25 s (limit 1.00)")


def test_late_input_stops_every_axis_and_is_logged_once_per_lapse(caplog):
    caplog.set_level(logging.WARNING, logger="g1_control.safety")
    f = SafetyFilter(SafetyConfig(input_zero_velocity_s=0.2, input_lost_s=1.0))
    walk = Command(vx_mps=0.5, vy_mps=0.3, wz_radps=0.2, style="wave", buttons=frozenset({"run"}))
    f.vet_input(walk, 0.0)
    stopped = f.vet_input(None, 0.5)
    assert (stopped.vx_mps, stopped.vy_mps, stopped.wz_radps, stopped.buttons) == (0.0, 0.0, 0.0, frozenset())
    assert stopped.style == "wave"
    f.vet_input(None, 0.6)
    f.vet_input(walk, 0.7)
    f.vet_input(None, 1.25)
    stale = [e for e in f.events if e.kind == SafetyEventKind.INPUT_STALE]
    assert [e.detail for e in stale] == ["no operator input for 0.50 s: velocity commands zeroed",
                                         "no operator input for 0.55 s: velocity commands zeroed"]
    assert all(e.trips is False for e in stale) and not f.tripped
    assert [r.levelno for r in caplog.records] == [logging.WARNING, logging.WARNING]


def test_the_estop_button_trip_says_where_it_came_from():
    f = SafetyFilter()
    f.vet_input(Command(buttons=frozenset({"estop"})), 1.0)
    _tripped(f, SafetyEventKind.ESTOP, "e-stop pressed on the operator input")


def test_deadline_trips_name_the_detail_only_when_given():
    f = SafetyFilter(SafetyConfig(overrun_burst_count=1))
    f.report_deadline(True, 0.0)
    _tripped(f, SafetyEventKind.DEADLINE_OVERRUNS, "1 deadline overruns within 1.0 s")
    g = SafetyFilter(SafetyConfig(overrun_burst_count=1))
    g.report_deadline(True, 0.0, "tick took 31 ms")
    _tripped(g, SafetyEventKind.DEADLINE_OVERRUNS, "1 deadline overruns within 1.0 s (tick took 31 ms)")


# -- events ---------------------------------------------------------------------------------------------
def test_the_constructors_callback_gets_every_event_and_faults_are_not_planned(caplog):
    caplog.set_level(logging.INFO, logger="g1_control.safety")
    seen = []
    f = SafetyFilter(on_event=seen.append)
    state = _state(imu_quat_wxyz=np.array([math.cos(0.6), math.sin(0.6), 0.0, 0.0]))
    assert not f.check(state, 0.0)
    assert seen == [f.trip_event] and seen[0].planned is False and seen[0].trips is True
    assert [r.levelno for r in caplog.records] == [logging.ERROR]


def test_a_fall_trips_once():
    f = SafetyFilter()
    f.report_fall("pelvis 0.31 m above the ground", 2.0)
    _tripped(f, SafetyEventKind.FALL, "pelvis 0.31 m above the ground")
    assert f.trip_event.t_s == 2.0 and not f.trip_event.planned
    f.report_fall("again", 3.0)
    assert len(f.events) == 1 and f.trip_event.detail == "pelvis 0.31 m above the ground"
