"""Tests that guard the safety code against the breakages a mutation run found surviving (issue 16):
gain caps (filter and config), the state validation added per tick (mode_machine, tick order,
range, non-finite fields by name), both sides of the tilt threshold, planned endings at INFO."""

from __future__ import annotations

import logging

import numpy as np
import pytest

from g1_control.errors import SafetyConfigError
from g1_control.robot import g1
from g1_control.safety import SafetyConfig, SafetyEventKind, SafetyFilter
from g1_control.safety.config import MAX_KD_CAP, MAX_KP_CAP
from tests.safety.safety_test_helpers import command as _cmd
from tests.safety.safety_test_helpers import state as _state


def _tilted(angle_rad: float) -> np.ndarray:
    return np.array([np.cos(angle_rad / 2), np.sin(angle_rad / 2), 0.0, 0.0])


def test_gains_above_the_caps_are_clamped_to_the_caps():
    f = SafetyFilter(SafetyConfig(max_kp=300.0, max_kd=10.0))
    out = f.filter(_cmd(kp=np.full(29, 5000.0), kd=np.full(29, 500.0)), _state(), 0.0)
    assert np.all(out.kp == 300.0) and np.all(out.kd == 10.0)
    assert f.clamps.per_joint["kp"].sum() == 29 and f.clamps.per_joint["kd"].sum() == 29
    below = f.filter(_cmd(kp=np.full(29, 299.0), kd=np.full(29, 9.0)), _state(0.002), 0.002)
    assert np.all(below.kp == 299.0) and np.all(below.kd == 9.0), "gains under the caps pass unchanged"


@pytest.mark.parametrize(("kwargs", "text"), [
    ({"max_kp": MAX_KP_CAP + 1}, "max_kp is 1001.0; the gain cap may be at most 1000"),
    ({"max_kd": MAX_KD_CAP + 1}, "max_kd is 101.0; the gain cap may be at most 100"),
    ({"max_kp": 0.0}, "max_kp is 0; it must be positive"),
    ({"max_kd": 0.0, "damping_kd": 0.0}, "is 0; it must be positive"),
    ({"max_kd": 1.0, "damping_kd": 2.0}, "damping_kd (2.0) exceeds max_kd (1.0)"),
    ({"max_quat_norm_error": 0.0}, "max_quat_norm_error is 0; it must be positive"),
])
def test_gain_caps_are_validated(kwargs, text):
    with pytest.raises(SafetyConfigError, match=text.replace("(", r"\(").replace(")", r"\)")):
        SafetyConfig(**kwargs)


def test_caps_at_their_bounds_are_accepted_and_clamp_there():
    f = SafetyFilter(SafetyConfig(max_kp=MAX_KP_CAP, max_kd=MAX_KD_CAP, damping_kd=MAX_KD_CAP))
    out = f.filter(_cmd(kp=np.full(29, 5000.0), kd=np.full(29, 500.0)), _state(), 0.0)
    assert np.all(out.kp == MAX_KP_CAP) and np.all(out.kd == MAX_KD_CAP)
    damping = f.damping()
    assert np.all(damping.kp == 0.0) and np.all(damping.kd == MAX_KD_CAP)


def test_tilt_trips_just_beyond_the_threshold_and_not_just_inside():
    for limit in (0.5, 1.0):
        inside = SafetyFilter(SafetyConfig(max_tilt_rad=limit))
        assert inside.check(_state(imu_quat_wxyz=_tilted(limit - 0.05)), 0.0)
        beyond = SafetyFilter(SafetyConfig(max_tilt_rad=limit))
        assert not beyond.check(_state(imu_quat_wxyz=_tilted(limit + 0.05)), 0.0)
        assert beyond.trip_event.kind == SafetyEventKind.TILT
        assert f"limit {limit:.2f}" in beyond.trip_event.detail


def test_a_mode_machine_change_trips_naming_both():
    f = SafetyFilter()
    f.expect_mode_machine(5)
    assert f.check(_state(0.0), 0.0)
    assert not f.check(_state(0.01, mode_machine=4), 0.01)
    assert f.trip_event.kind == SafetyEventKind.MODE_MACHINE_CHANGED
    assert "mode_machine changed from 5 to 4" in f.trip_event.detail
    assert f.filter(_cmd(), _state(0.02), 0.02).kp.max() == 0.0, "damping for good"


def test_the_first_mode_machine_seen_is_expected_when_none_was_given():
    f = SafetyFilter()
    assert f.check(_state(0.0, mode_machine=6), 0.0)
    assert f.expected_mode_machine == 6
    assert not f.check(_state(0.01, mode_machine=5), 0.01)


def test_a_tick_running_back_trips_but_wraparound_does_not():
    f = SafetyFilter()
    assert f.check(_state(0.0, tick=2**32 - 2), 0.0)
    assert f.check(_state(0.01, tick=3), 0.01), "u32 wraparound is a step forward"
    assert f.check(_state(0.02, tick=8), 0.02)
    assert not f.check(_state(0.03, tick=5), 0.03)
    assert f.trip_event.kind == SafetyEventKind.STATE_OUT_OF_RANGE
    assert "tick went back from 8 to 5" in f.trip_event.detail


def test_a_joint_far_outside_its_limits_trips_naming_it():
    knee = g1.JOINT_INDEX["left_knee_joint"]
    near = _state()
    near.q_rad[knee] = g1.Q_MAX_RAD[knee] + 0.2
    assert SafetyFilter().check(near, 0.0), "within state_limit_margin_rad (an end stop, sim overshoot)"
    far = _state()
    far.q_rad[knee] = g1.Q_MIN_RAD[knee] - 0.3
    f = SafetyFilter()
    assert not f.check(far, 0.0)
    assert f.trip_event.kind == SafetyEventKind.STATE_OUT_OF_RANGE and "left_knee_joint" in f.trip_event.detail


def test_a_quaternion_that_is_not_unit_trips():
    f = SafetyFilter()
    assert not f.check(_state(imu_quat_wxyz=np.array([0.5, 0.0, 0.0, 0.0])), 0.0)
    assert "imu_quat_wxyz has norm 0.500" in f.trip_event.detail
    assert SafetyFilter().check(_state(imu_quat_wxyz=np.array([1.05, 0.0, 0.0, 0.0])), 0.0)


@pytest.mark.parametrize("field", ["q_rad", "dq_radps", "tau_nm", "imu_gyro_radps", "imu_acc_mps2",
                                   "motor_temperature_c"])
def test_each_nonfinite_field_trips_naming_it(field):
    state = _state()
    arr = np.array(getattr(state, field), dtype=float)
    arr[1] = np.inf if field == "tau_nm" else np.nan
    setattr(state, field, arr)
    f = SafetyFilter()
    assert not f.check(state, 0.0)
    assert f.trip_event.kind == SafetyEventKind.NONFINITE_STATE
    assert f"RobotState.{field} contains NaN or inf" in f.trip_event.detail


def test_a_peer_fault_trips_and_none_does_not():
    f = SafetyFilter()
    assert f.report_peers(None, 0.0) and f.report_peers("", 0.0)
    assert not f.report_peers("2 publishers on rt/lowstate", 0.1)
    assert f.trip_event.kind == SafetyEventKind.FOREIGN_PEER and f.trip_event.detail == "2 publishers on rt/lowstate"


def test_overruns_count_only_beyond_the_lateness_allowed():
    f = SafetyFilter(SafetyConfig(overrun_burst_count=2, overrun_lateness_s=0.05))
    assert f.report_deadline(False, 0.0) and f.report_deadline(False, 0.01)
    assert f.report_deadline(True, 0.02)
    assert not f.report_deadline(True, 0.03)


def test_planned_endings_log_at_info_and_faults_at_error(caplog):
    caplog.set_level(logging.INFO, logger="g1_control.safety")
    SafetyFilter().estop("control time over (5.0 s)", 1.0, planned=True)
    SafetyFilter().estop("e-stop pressed", 1.0)
    levels = {r.getMessage().split(": ", 1)[1]: r.levelno for r in caplog.records}
    assert levels == {"control time over (5.0 s)": logging.INFO, "e-stop pressed": logging.ERROR}
