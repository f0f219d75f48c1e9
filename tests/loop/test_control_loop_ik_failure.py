"""An IK with no solution is a typed safety event, not an exception out of the loop (issue 26): the
real IK stage (IKStage, IKRetargeter) on a stand-in robot, its QP solver made to find nothing on the
ticks a test chooses (every solve, the relaxed retries too, fails as daqp's infeasible exit does).
A failure held for up to safety.ik_hold_ticks tracker ticks keeps the last good reference and the
run goes on; one more failure in a row, or a failure before any good reference, damps for good with
an `ik_failure` trip that names the IK's error."""

from __future__ import annotations

import numpy as np
import pytest

from g1_control.errors import RetargetError
from g1_control.ik.exceptions import NoSolutionFound
from g1_control.ik.retargeter import IKConfig
from g1_control.ik.stage import IKStage
from g1_control.interfaces import Generator, Tracker
from g1_control.loop.control_loop import ControlLoop, first_fault
from g1_control.robot import g1
from g1_control.safety import SafetyConfig, SafetyEventKind, SafetyFilter
from g1_control.types import KinematicReference, MotorCommand, RobotState
from tests.loop.test_control_loop_trips import StandInRobot, Still

INFEASIBLE = "daqp found no IK step (exit flag -1: infeasible constraints)"
TRACKER_DT_S = 0.02
"""The loop's default tracker rate is 50 Hz: loop.run(0.02) runs exactly one tracker tick (once aligned)."""


class Standing(Generator):
    """A standing reference that the IK has to solve (no feasible plan: the IK stage runs every tick)."""

    def update(self, command, state: RobotState) -> KinematicReference:
        ref = KinematicReference(t_s=state.t_s, q_rad=g1.DEFAULT_Q_RAD.copy())
        ref.root_pos_w_m[2] = g1.DEFAULT_PELVIS_HEIGHT_M
        return ref


class Recording(Tracker):
    """Holds the default pose; records the joint references it is given."""

    def __init__(self):
        self.references = []

    def act(self, reference, state) -> MotorCommand:
        self.references.append(reference)
        return MotorCommand(q_rad=g1.DEFAULT_Q_RAD.copy(), kp=g1.KP_DEFAULT.copy(), kd=g1.KD_DEFAULT.copy())


class SolverFault:
    """While `on`, the IK's QP solver finds no step (NoSolutionFound, as from daqp's infeasible exit)."""

    def __init__(self, stage: IKStage):
        self.on, self.calls = False, 0
        self._solve = stage.ik.solver.solve
        stage.ik.solver.solve = self.solve  # type: ignore[method-assign]

    def solve(self, *args, **kwargs):
        self.calls += 1
        if self.on:
            raise NoSolutionFound(INFEASIBLE)
        return self._solve(*args, **kwargs)


@pytest.fixture(scope="module")
def ik_config() -> IKConfig:
    return IKConfig(hold_contacts=False, com_cost=(0.0, 0.0, 0.0))


def _loop(ik_config: IKConfig, hold_ticks: int = 3):
    robot, tracker, stage = StandInRobot(), Recording(), IKStage(ik_config)
    fault = SolverFault(stage)
    safety = SafetyFilter(SafetyConfig(ik_hold_ticks=hold_ticks))
    loop = ControlLoop(robot, Still(), Standing(), stage, tracker, safety=safety)
    records: list[dict] = []
    loop.on_record = records.append
    loop.reset()
    return loop, robot, tracker, stage, fault, records


def test_the_ik_error_is_the_loops_retarget_error():
    assert issubclass(NoSolutionFound, RetargetError)


def test_one_failed_tick_holds_the_last_good_reference_and_the_run_goes_on(ik_config):
    loop, robot, tracker, stage, fault, records = _loop(ik_config)
    loop.run(0.1)
    solved = stage.solved_ticks
    assert solved == 5 and len(tracker.references) == 5
    last_good = tracker.references[-1]
    fault.on = True
    loop.run(TRACKER_DT_S)
    fault.on = False
    assert stage.solved_ticks == solved  # this tick's solve failed ...
    assert tracker.references[-1] is last_good  # ... and the tracker acted on the last good reference
    assert len(tracker.references) == 6
    loop.run(0.1)
    assert stage.solved_ticks == solved + 5 and tracker.references[-1] is not last_good
    assert not loop.faulted and loop.safety.ik_held_ticks == 1
    assert np.all(loop.motor_command.kp > 0) and np.all(robot.last_command.kp > 0)
    [event] = loop.events
    assert (event.kind, event.trips, event.planned) == ("ik_hold", False, False)
    assert event.detail == ("the IK found no solution: the last good reference is held (up to 3 tracker ticks): "
                            f"NoSolutionFound: {INFEASIBLE}")
    assert event.t_s == pytest.approx(0.1)
    assert str(event) == f"ik_hold: {event.detail}"  # not a trip: no "(damping)"
    assert [r["kind"] for r in records] == ["ik_hold"] and records[0]["trips"] is False
    assert first_fault(records) is None


def test_a_persistent_failure_damps_with_a_typed_ik_failure_trip(ik_config):
    loop, robot, tracker, _stage, fault, records = _loop(ik_config, hold_ticks=3)
    loop.run(0.1)
    last_good = tracker.references[-1]
    fault.on = True
    loop.run(3 * TRACKER_DT_S)  # three failures in a row: held
    assert not loop.faulted and loop.safety.ik_held_ticks == 3
    assert tracker.references[-3:] == [last_good] * 3 and np.all(robot.last_command.kp > 0)
    loop.run(TRACKER_DT_S)  # the fourth: damping
    trip = loop.safety.trip_event
    assert trip is not None and trip.kind == SafetyEventKind.IK_FAILURE and trip.trips and not trip.planned
    assert trip.detail == ("the IK found no solution on 4 tracker ticks in a row (safety.ik_hold_ticks 3): "
                           f"NoSolutionFound: {INFEASIBLE}")
    assert trip.t_s == pytest.approx(0.1 + 3 * TRACKER_DT_S)
    assert len(tracker.references) == 8  # the tracker no longer acts once tripped
    damping = loop.safety.damping()
    for command in (loop.motor_command, robot.last_command):
        assert np.all(command.kp == 0) and np.array_equal(command.kd, damping.kd)
    loop.run(0.1)  # damping for good, even once the IK finds solutions again
    fault.on = False
    loop.run(0.1)
    assert np.all(robot.last_command.kp == 0) and len(tracker.references) == 8
    assert [(e.kind, e.trips) for e in loop.events] == [("ik_hold", False), ("ik_failure", True)]
    fault_record = first_fault(records)
    assert fault_record is not None and fault_record["kind"] == "ik_failure" and fault_record["detail"] == trip.detail
    assert str(loop.events[-1]) == f"ik_failure (damping): {trip.detail}"


def test_failures_with_good_ticks_between_them_never_add_up(ik_config):
    loop, robot, _tracker, _stage, fault, _records = _loop(ik_config, hold_ticks=1)
    loop.run(0.1)
    for _ in range(5):
        fault.on = True
        loop.run(TRACKER_DT_S)
        fault.on = False
        loop.run(TRACKER_DT_S)
    assert not loop.faulted and loop.safety.ik_held_ticks == 5
    assert [e.kind for e in loop.events] == ["ik_hold"] * 5  # one per run of failures
    assert np.all(robot.last_command.kp > 0)


def test_no_hold_damps_on_the_first_failure(ik_config):
    loop, robot, tracker, _stage, fault, _records = _loop(ik_config, hold_ticks=0)
    loop.run(0.1)
    fault.on = True
    loop.run(TRACKER_DT_S)
    trip = loop.safety.trip_event
    assert trip is not None and trip.kind == SafetyEventKind.IK_FAILURE
    assert trip.detail.startswith("the IK found no solution on 1 tracker ticks in a row (safety.ik_hold_ticks 0): ")
    assert len(tracker.references) == 5 and np.all(robot.last_command.kp == 0)
    assert [e.kind for e in loop.events] == ["ik_failure"]


def test_a_failure_before_any_good_reference_damps_at_once(ik_config):
    loop, robot, tracker, _stage, fault, _records = _loop(ik_config, hold_ticks=3)
    fault.on = True
    loop.run(0.1)
    trip = loop.safety.trip_event
    assert trip is not None and trip.kind == SafetyEventKind.IK_FAILURE and trip.t_s == 0.0
    assert trip.detail == f"the IK found no solution before any good reference to hold: NoSolutionFound: {INFEASIBLE}"
    assert tracker.references == [] and np.all(robot.last_command.kp == 0)
