from __future__ import annotations

import numpy as np

from g1_control.robot import g1
from g1_control.safety import GuardedBackend, SafetyEventKind
from g1_control.sim.mock_robot import MockG1
from g1_control.types import MotorCommand


def test_lockstep_backend_gets_clamped_commands_and_sim_time():
    robot = GuardedBackend(MockG1())
    robot.reset()
    cmd = MotorCommand(q_rad=g1.DEFAULT_Q_RAD.copy(), kp=g1.KP_DEFAULT.copy(), kd=g1.KD_DEFAULT.copy())
    cmd.q_rad[3] = 10.0  # knee far beyond its limit
    for _ in range(200):
        robot.write_command(cmd)
        robot.step(0.002)
    assert robot.last_sent.q_rad[3] <= g1.Q_MAX_RAD[3]
    # What the motors were given (MockG1 keeps the last command; it clips its own joints, so the
    # state cannot tell whether the guard clamped): the clamped target, not the 10 rad asked for.
    assert robot.inner._command.q_rad[3] <= g1.Q_MAX_RAD[3]
    assert robot.inner._command.q_rad[3] == robot.last_sent.q_rad[3]
    assert robot.safety.clamps.per_joint["q_rad"][3] == 200 and not robot.safety.tripped


def test_estop_damps_the_inner_backend_at_once():
    inner = MockG1()
    robot = GuardedBackend(inner, clock=lambda: 5.0)
    robot.reset()
    robot.estop("operator pressed the e-stop")
    assert np.all(inner._command.kp == 0) and np.all(inner._command.kd > 0)
    assert robot.safety.trip_event.kind == SafetyEventKind.ESTOP and robot.safety.trip_event.t_s == 5.0


def test_repeated_overruns_trip_through_the_wrapper():
    robot = GuardedBackend(MockG1(), clock=lambda: 1.0)
    robot.reset()
    for _ in range(5):
        robot.report_deadline(True, "tick took 30 ms")
    assert robot.safety.trip_event.kind == SafetyEventKind.DEADLINE_OVERRUNS
