import numpy as np
import pytest
from test_ik_frame_task import fd_jacobian, random_configuration

from g1_control.ik.exceptions import TaskDefinitionError
from g1_control.ik.tasks import ComTask


def test_com_task_jacobian_matches_finite_differences():
    conf = random_configuration(6)
    task = ComTask()
    task.set_target(np.array([0.1, 0.0, 0.6]))
    np.testing.assert_allclose(task.compute_jacobian(conf), fd_jacobian(task, conf), atol=1e-6)


def test_com_error_is_com_minus_target():
    conf = random_configuration(7)
    task = ComTask()
    task.set_target(conf.com_w_m + np.array([0.0, 0.05, 0.0]))
    np.testing.assert_allclose(task.compute_error(conf), [0.0, -0.05, 0.0], atol=1e-12)


def test_com_target_must_be_three_numbers():
    with pytest.raises(TaskDefinitionError, match="3 finite numbers"):
        ComTask().set_target(np.array([0.0, np.nan, 0.0]))
    with pytest.raises(TaskDefinitionError, match=r"shape \(1,\) or \(3,\). Got \(4,\)"):
        ComTask(cost=np.ones(4))
