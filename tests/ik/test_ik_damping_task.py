import numpy as np

from g1_control.ik.configuration import Configuration
from g1_control.ik.tasks import DampingTask, SmoothnessTask, Task


def test_damping_adds_squared_cost_on_the_diagonal_only():
    conf = Configuration()
    h, c = DampingTask(0.1).compute_qp_objective(conf)
    np.testing.assert_allclose(h, np.eye(conf.nv) * 0.01)
    assert np.all(c == 0.0)


def test_smoothness_pulls_toward_the_previous_step():
    conf = Configuration()
    task = SmoothnessTask(0.5)
    prev = np.linspace(-1, 1, conf.nv)
    task.set_previous_step(prev)
    h, c = task.compute_qp_objective(conf)
    # minimiser of 1/2 x^T H x + c^T x is the previous step
    np.testing.assert_allclose(np.linalg.solve(h, -c), prev, atol=1e-12)
    h_ref, c_ref = np.zeros_like(h), np.zeros_like(c)
    Task.add_objective(task, conf, h_ref, c_ref)
    np.testing.assert_allclose(h, h_ref)
    np.testing.assert_allclose(c, c_ref)
