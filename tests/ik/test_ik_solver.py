import numpy as np
import pytest

from g1_control.ik.configuration import Configuration
from g1_control.ik.exceptions import IKError, NoSolutionFound
from g1_control.ik.limits import (
    BoxBounds,
    GroundLimit,
    JointPositionLimit,
    JointVelocityLimit,
    Limit,
    RowConstraint,
)
from g1_control.ik.solver import QPSolver
from g1_control.ik.tasks import DampingTask, FrameTask, PostureTask
from g1_control.robot import g1


def _problem():
    conf = Configuration()
    hand = FrameTask("left_rubber_hand", 1.0, 0.0)
    hand.set_target_from_configuration(conf)
    hand.set_target_position(hand.target.translation + np.array([0.3, 0.0, 0.2]))
    posture = PostureTask(0.05)
    posture.set_target(np.asarray(g1.DEFAULT_Q_RAD))
    return conf, [hand, posture, DampingTask(1e-3)], [JointPositionLimit(), JointVelocityLimit(), GroundLimit()]


def test_backends_agree_on_the_step():
    conf, tasks, limits = _problem()
    a = QPSolver(backend="daqp").solve(conf, tasks, limits, 0.02)
    b = QPSolver(backend="proxqp", tolerance=1e-9).solve(conf, tasks, limits, 0.02)
    np.testing.assert_allclose(a, b, atol=1e-5)


def test_step_respects_velocity_box_and_reduces_the_error():
    conf, tasks, limits = _problem()
    dq = QPSolver().solve(conf, tasks, limits, 0.02)
    assert np.all(np.abs(dq[6:]) <= g1.VELOCITY_LIMIT_RADPS * 0.02 + 1e-7)
    before = np.linalg.norm(tasks[0].compute_error(conf)[:3])
    conf.integrate_inplace(dq)
    assert np.linalg.norm(tasks[0].compute_error(conf)[:3]) < before


class _Contradiction(Limit):
    def compute(self, configuration, dt_s):
        row = np.zeros((2, configuration.nv))
        row[:, 10] = 1.0
        return RowConstraint(row, np.array([1.0, -INF_]), np.array([INF_, -1.0]))


INF_ = 1e30


def test_infeasible_constraints_raise_no_solution_found():
    conf, tasks, _ = _problem()
    for backend in ("daqp", "proxqp"):
        with pytest.raises(NoSolutionFound):
            QPSolver(backend=backend).solve(conf, tasks, [_Contradiction()], 0.02)


def test_unknown_backend_is_named():
    with pytest.raises(IKError, match="unknown QP backend 'cvx'; known: daqp, proxqp"):
        QPSolver(backend="cvx")


def test_overlapping_boxes_keep_the_tighter_bound():
    class Box(Limit):
        def __init__(self, lo, hi):
            self.lo, self.hi = lo, hi

        def compute(self, configuration, dt_s):
            return BoxBounds(np.full(configuration.nv, self.lo), np.full(configuration.nv, self.hi))

    conf, tasks, _ = _problem()
    solver = QPSolver()
    solver.build(conf, tasks, [Box(-1.0, 0.5), Box(-0.2, 2.0)], 0.02)
    assert np.all(solver.lower == -0.2) and np.all(solver.upper == 0.5)
