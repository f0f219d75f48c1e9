from __future__ import annotations

import math

import numpy as np
import pytest

from g1_control.errors import SafetyConfigError
from g1_control.robot import g1
from g1_control.rotations import tilt_rad
from g1_control.safety import SafetyConfig, SafetyEventKind, SafetyFilter
from g1_control.types import Command, MotorCommand
from tests.safety.safety_test_helpers import command as _cmd
from tests.safety.safety_test_helpers import state as _state


def _is_damping(cmd: MotorCommand, kd=2.0) -> bool:
    return bool(np.all(cmd.kp == 0) and np.all(cmd.kd == kd) and np.all(cmd.tau_nm == 0))


def test_in_limit_command_passes_unchanged_and_uncounted():
    f = SafetyFilter()
    out = f.filter(_cmd(), _state(), now_s=0.01)
    np.testing.assert_array_equal(out.q_rad, g1.DEFAULT_Q_RAD)
    np.testing.assert_array_equal(out.kp, g1.KP_DEFAULT)
    assert f.clamps.total == 0 and not f.tripped


def test_out_of_limit_fields_are_clamped_and_counted_per_joint():
    f = SafetyFilter()
    cmd = _cmd()
    knee = g1.JOINT_INDEX["left_knee_joint"]
    cmd.q_rad[knee] = 5.0
    cmd.tau_nm[0] = -1000.0
    cmd.dq_radps[20] = 100.0
    cmd.kp[1] = -3.0
    out = f.filter(cmd, _state(), 0.0)
    assert out.q_rad[knee] <= g1.Q_MAX_RAD[knee] and out.q_rad[knee] == pytest.approx(g1.Q_MAX_RAD[knee])
    assert out.tau_nm[0] == pytest.approx(-g1.EFFORT_LIMIT_NM[0])
    assert out.dq_radps[20] == pytest.approx(g1.VELOCITY_LIMIT_RADPS[20])
    assert out.kp[1] == 0.0
    assert f.clamps.per_joint["q_rad"][knee] == 1 and f.clamps.per_joint["tau_nm"][0] == 1
    assert f.clamps.total == 4 and f.clamps.commands == 1
    assert cmd.q_rad[knee] == 5.0, "the caller's command is not modified"


def test_clamped_targets_stay_inside_limits_after_float32_rounding():
    f = SafetyFilter()
    cmd = _cmd()
    cmd.q_rad[:] = 100.0
    out = f.filter(cmd, _state(), 0.0)
    assert np.all(out.q_rad.astype(np.float32).astype(np.float64) <= g1.Q_MAX_RAD)


@pytest.mark.parametrize("mutate, now_s, kind, text", [
    (lambda s: None, 0.051, SafetyEventKind.STALE_STATE, "newest state is 51.0 ms old (limit 50 ms)"),
    (lambda s: setattr(s, "imu_quat_wxyz", np.array([math.cos(0.6), math.sin(0.6), 0.0, 0.0])), 0.0,
     SafetyEventKind.TILT, "pelvis tilted 1.20 rad (limit 1.00)"),
    (lambda s: s.dq_radps.__setitem__(3, -21.0), 0.0, SafetyEventKind.JOINT_OVERSPEED,
     "left_knee_joint moves at -21.0 rad/s (limit 20.0)"),
    (lambda s: s.q_rad.__setitem__(5, np.nan), 0.0, SafetyEventKind.NONFINITE_STATE, "RobotState.q_rad contains NaN"),
    (lambda s: s.motor_temperature_c.__setitem__(12, 95.0), 0.0, SafetyEventKind.OVER_TEMPERATURE,
     "waist_yaw_joint motor at 95 °C (limit 90)"),
])
def test_each_state_fault_trips_to_damping_for_good(mutate, now_s, kind, text):
    f = SafetyFilter()
    bad = _state()
    mutate(bad)
    out = f.filter(_cmd(), bad, now_s)
    assert _is_damping(out)
    assert f.trip_event.kind == kind and text in f.trip_event.detail
    # A perfectly good state afterwards changes nothing: damping for good, one trip event.
    assert _is_damping(f.filter(_cmd(), _state(t_s=1.0), 1.0))
    assert [e.kind for e in f.events] == [kind]


def test_frozen_tick_counts_as_stale_state():
    f = SafetyFilter()
    for i in range(3):  # fresh samples with an advancing tick
        assert f.check(_state(t_s=i * 0.02, tick=i), i * 0.02)
    assert f.check(_state(t_s=0.06, tick=2), 0.06)  # same tick, 20 ms: fine
    assert not f.check(_state(t_s=0.10, tick=2), 0.10)  # same tick, 60 ms: frozen
    assert f.trip_event.kind == SafetyEventKind.STALE_STATE
    assert "tick frozen at 2 for 60.0 ms" in f.trip_event.detail


def test_nonfinite_command_trips():
    f = SafetyFilter()
    cmd = _cmd()
    cmd.tau_nm[2] = np.inf
    assert _is_damping(f.filter(cmd, _state(), 0.0))
    assert f.trip_event.kind == SafetyEventKind.NONFINITE_COMMAND and "tau_nm" in f.trip_event.detail


def test_crc_burst_trips_but_sparse_errors_do_not():
    f = SafetyFilter(SafetyConfig(crc_burst_count=5, crc_burst_window_s=0.1))
    for i in range(1, 6):
        assert f.report_crc_errors(i, now_s=i * 0.5)  # one bad sample every 0.5 s: only counted
    assert not f.tripped
    assert f.report_crc_errors(10, now_s=3.0) is False  # five more at once -> five within 100 ms
    assert f.trip_event.kind == SafetyEventKind.CRC_BURST and "(10 in total)" in f.trip_event.detail


def test_repeated_deadline_overruns_trip():
    f = SafetyFilter(SafetyConfig(overrun_burst_count=3, overrun_window_s=1.0))
    assert f.report_deadline(True, 0.0) and f.report_deadline(False, 0.1) and f.report_deadline(True, 0.2)
    assert f.report_deadline(True, 0.3, detail="tick took 31 ms") is False
    assert f.trip_event.kind == SafetyEventKind.DEADLINE_OVERRUNS and "tick took 31 ms" in f.trip_event.detail


def test_input_loss_zeroes_velocity_first_then_damps():
    f = SafetyFilter(SafetyConfig(input_zero_velocity_s=0.2, input_lost_s=1.0))
    walk = Command(vx_mps=0.5, wz_radps=0.3, buttons=frozenset({"run"}))
    assert f.vet_input(walk, 0.0) is walk
    held = f.vet_input(None, 0.1)
    assert held.vx_mps == 0.5 and held.buttons == frozenset(), "a button edge is not repeated"
    stopped = f.vet_input(None, 0.5)
    assert stopped.vx_mps == 0.0 and stopped.wz_radps == 0.0
    assert f.events[-1].kind == SafetyEventKind.INPUT_STALE and not f.tripped
    assert f.check(_state(t_s=0.99), 0.99)
    assert not f.check(_state(t_s=1.01), 1.01)
    assert f.trip_event.kind == SafetyEventKind.INPUT_LOST


def test_input_watchdog_is_not_armed_without_input():
    f = SafetyFilter()
    assert f.vet_input(None, 100.0) == Command()
    assert f.check(_state(t_s=100.0), 100.0)


def test_estop_button_and_explicit_estop_trip():
    f = SafetyFilter()
    f.vet_input(Command(buttons=frozenset({"estop"})), 2.0)
    assert f.trip_event.kind == SafetyEventKind.ESTOP and f.trip_event.t_s == 2.0
    g = SafetyFilter()
    events = []
    g.on_event = events.append
    g.estop("SIGTERM received", 3.0)
    assert _is_damping(g.filter(_cmd(), _state(t_s=3.0), 3.0))
    assert str(events[0]) == "[3.000 s] estop (damping): SIGTERM received"


def test_tilt_of_known_rotations():
    assert tilt_rad(np.array([1.0, 0, 0, 0])) == 0.0
    half = math.pi / 4
    assert tilt_rad(np.array([math.cos(half), 0, math.sin(half), 0])) == pytest.approx(math.pi / 2)
    assert tilt_rad(np.array([math.cos(half), 0, 0, math.sin(half)])) == pytest.approx(0.0, abs=1e-7), "yaw is no tilt"


@pytest.mark.parametrize("kwargs, text", [
    ({"stale_state_s": -1.0}, "stale_state_s is -1.0; it must not be negative"),
    ({"max_tilt_rad": float("nan")}, "max_tilt_rad is nan; it must be a finite number"),
    ({"crc_burst_count": 0}, "crc_burst_count is 0; it must be a whole number >= 1"),
    ({"input_lost_s": 0.1}, "input_lost_s (0.1) must not be shorter than input_zero_velocity_s (0.2): the robot "
                            "stops before it damps"),
    ({"stale_state_s": 0.0}, "stale_state_s is 0; it must be positive"),
    ({"max_tilt_rad": math.pi}, "max_tilt_rad is 3.141592653589793; it must be below pi (3.1416 rad): no tilt "
                                "exceeds pi, so the tilt trip could never fire"),
    ({"max_motor_temperature_c": 120.5}, "max_motor_temperature_c is 120.5 °C; it may be at most the motors' rating, "
                                         "120 °C (a hotter threshold trips only after the damage)"),
    ({"command_hold_ticks": 1.0}, "command_hold_ticks is 1.0; it must be 0 (never hold) or at least 1.5 tracker ticks "
                                  "(a tick may come half a period late, and a command must last until the next one)"),
    ({"command_hold_ticks": -3.0}, "command_hold_ticks is -3.0; it must not be negative"),
])
def test_bad_config_is_refused_by_name(kwargs, text):
    with pytest.raises(SafetyConfigError) as info:
        SafetyConfig(**kwargs)
    assert str(info.value) == f"SafetyConfig.{text}"


def test_the_tilt_and_temperature_bounds_are_inclusive_where_a_trip_can_still_fire():
    """Just below pi a robot lying on its back still trips; the motors' rating itself is a threshold."""
    below_pi = math.nextafter(math.pi, 0.0)
    upside_down = np.array([0.0, 1.0, 0.0, 0.0])
    assert SafetyFilter(SafetyConfig(max_tilt_rad=below_pi)).check(_state(imu_quat_wxyz=upside_down), 0.0) is False
    SafetyConfig(max_motor_temperature_c=g1.MOTOR_MAX_TEMPERATURE_C)
    SafetyConfig(command_hold_ticks=1.5)
    SafetyConfig(command_hold_ticks=0)  # never hold
