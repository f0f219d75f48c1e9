"""GuardedBackend's wiring (mutation-run survivors, issue 16): its config and callback reach the filter,
each clock is the right one, the link's bad CRCs and peer faults trip through it, overruns damp only
once they trip, e-stops are faults unless planned, the signal handler e-stops and unwinds."""

from __future__ import annotations

import math
import signal

import numpy as np
import pytest

from g1_control.safety import GuardedBackend, SafetyConfig, SafetyEventKind
from g1_control.safety.guarded_backend import install_signal_damping
from g1_control.sim.mock_robot import MockG1
from g1_control.types import MotorCommand
from tests.safety.safety_test_helpers import command as _cmd


class _Link(MockG1):
    """A stand-in robot link: wall-clock unless told otherwise, with the link's counters."""

    def __init__(self, lockstep=False):
        super().__init__()
        self.lockstep = lockstep
        self.crc, self.fault, self.damped = 0, None, 0

    @property
    def bad_crc(self) -> int:
        return self.crc

    @property
    def peer_fault(self):
        return self.fault

    def damp(self) -> None:
        self.damped += 1
        super().damp()


def _damping(cmd: MotorCommand) -> bool:
    return bool(np.all(cmd.kp == 0) and np.all(cmd.kd > 0))


def test_the_config_and_callback_reach_the_filter():
    seen = []
    robot = GuardedBackend(MockG1(), SafetyConfig(max_kp=10.0, max_kd=5.0, damping_kd=1.0), on_event=seen.append)
    robot.reset()
    assert robot.lockstep is True and robot.last_sent is None
    robot.write_command(_cmd())
    assert robot.last_sent.kp.max() == 10.0
    robot.estop("stop")
    assert [e.kind for e in seen] == [SafetyEventKind.ESTOP] and np.all(robot.inner._command.kd == 1.0)


def test_a_wall_clock_backend_is_judged_on_the_monotonic_clock():
    inner = _Link(lockstep=False)
    robot = GuardedBackend(inner)
    assert robot.lockstep is False
    robot.write_command(_cmd())  # the state is stamped 0.0; the monotonic clock is far later
    assert robot.safety.trip_event.kind == SafetyEventKind.STALE_STATE


def test_a_given_clock_is_used_for_states():
    robot = GuardedBackend(MockG1(), clock=lambda: 123.0)
    state = robot.reset()
    assert robot.now_s(state) == 123.0
    lockstep = GuardedBackend(MockG1())
    state = lockstep.reset()
    state.t_s = 4.5
    assert lockstep.now_s(state) == 4.5


def test_bad_crcs_of_the_link_trip_at_the_clocks_time():
    inner = _Link()
    robot = GuardedBackend(inner, SafetyConfig(crc_burst_count=3), clock=lambda: 0.0)
    robot.write_command(_cmd())
    assert not robot.safety.tripped
    inner.crc = 3
    robot.write_command(_cmd())
    assert robot.safety.trip_event.kind == SafetyEventKind.CRC_BURST and robot.safety.trip_event.t_s == 0.0
    assert _damping(inner._command)


def test_a_peer_fault_of_the_link_trips():
    inner = _Link()
    robot = GuardedBackend(inner, clock=lambda: 0.0)
    inner.fault = "2 publishers on rt/lowstate"
    robot.write_command(_cmd())
    event = robot.safety.trip_event
    assert (event.kind, event.detail, event.t_s) == (SafetyEventKind.FOREIGN_PEER, "2 publishers on rt/lowstate", 0.0)
    assert _damping(inner._command) and _damping(robot.last_sent)


def test_overruns_damp_the_link_only_once_they_trip():
    inner = _Link(lockstep=True)
    robot = GuardedBackend(inner, SafetyConfig(overrun_burst_count=2), clock=lambda: 7.5)
    robot.report_deadline(True)
    assert inner.damped == 0 and not _damping(inner._command)
    robot.report_deadline(True)
    event = robot.safety.trip_event
    assert (event.kind, event.detail, event.t_s) == (SafetyEventKind.DEADLINE_OVERRUNS,
                                                     "2 deadline overruns within 1.0 s", 7.5)
    assert inner.damped == 1 and _damping(inner._command)


def test_overruns_on_a_lockstep_backend_take_the_simulation_time():
    inner = _Link(lockstep=True)
    robot = GuardedBackend(inner, SafetyConfig(overrun_burst_count=1))
    inner.reset()
    inner._t = 2.25
    robot.report_deadline(True, "tick took 31 ms")
    event = robot.safety.trip_event
    assert event.t_s == 2.25 and event.detail == "1 deadline overruns within 1.0 s (tick took 31 ms)"


def test_an_estop_is_a_fault_unless_planned_and_works_without_a_clock():
    robot = GuardedBackend(MockG1())
    robot.estop("operator pressed the e-stop")
    event = robot.safety.trip_event
    assert event.detail == "operator pressed the e-stop" and event.planned is False and math.isnan(event.t_s)
    planned = GuardedBackend(MockG1(), clock=lambda: 3.0)
    planned.estop("control time over", planned=True)
    assert planned.safety.trip_event.planned is True and planned.safety.trip_event.t_s == 3.0


def test_the_signal_handler_estops_then_unwinds():
    robot = GuardedBackend(MockG1(), clock=lambda: 1.0)
    previous = signal.getsignal(signal.SIGUSR1)
    try:
        install_signal_damping(robot, signals=(signal.SIGUSR1,))
        with pytest.raises(KeyboardInterrupt):
            signal.raise_signal(signal.SIGUSR1)
    finally:
        signal.signal(signal.SIGUSR1, previous)
    event = robot.safety.trip_event
    assert (event.kind, event.detail, event.planned) == (SafetyEventKind.ESTOP, "SIGUSR1 received", True)
    assert _damping(robot.inner._command)
