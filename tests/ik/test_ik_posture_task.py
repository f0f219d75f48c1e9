import numpy as np
import pytest
from test_ik_frame_task import fd_jacobian, random_configuration

from g1_control.ik.exceptions import TaskDefinitionError
from g1_control.ik.tasks import PostureTask, Task
from g1_control.robot import g1


def test_posture_jacobian_matches_finite_differences():
    conf = random_configuration(8)
    task = PostureTask()
    task.set_target(np.asarray(g1.DEFAULT_Q_RAD))
    np.testing.assert_allclose(task.compute_jacobian(conf), fd_jacobian(task, conf), atol=1e-8)


def test_posture_shortcut_objective_equals_the_generic_formula():
    conf = random_configuration(9)
    cost = np.linspace(0.1, 2.0, g1.NUM_JOINTS)
    task = PostureTask(cost, gain=0.7, lm_damping=0.3)
    task.set_target(np.asarray(g1.DEFAULT_Q_RAD))
    h_fast, c_fast = task.compute_qp_objective(conf)
    h_ref, c_ref = np.zeros_like(h_fast), np.zeros_like(c_fast)
    Task.add_objective(task, conf, h_ref, c_ref)
    np.testing.assert_allclose(h_fast, h_ref, atol=1e-12)
    np.testing.assert_allclose(c_fast, c_ref, atol=1e-12)


def test_posture_target_shape_is_checked():
    with pytest.raises(TaskDefinitionError, match="29 finite joint angles"):
        PostureTask().set_target(np.zeros(12))
