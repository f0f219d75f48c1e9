import numpy as np
import pinocchio as pin
import pytest
from test_ik_frame_task import fd_jacobian, random_configuration

from g1_control.ik.exceptions import TaskDefinitionError
from g1_control.ik.tasks import RelativeFrameTask


@pytest.mark.parametrize("frame,root", [("left_rubber_hand", "torso_link"), ("left_ankle_roll_link", "right_toe")])
def test_relative_frame_task_jacobian_matches_finite_differences(frame, root):
    conf = random_configuration(4)
    task = RelativeFrameTask(frame, root)
    task.set_target(pin.SE3(pin.utils.rpyToMatrix(0.2, 0.1, -0.4), np.array([0.3, 0.2, -0.1])))
    np.testing.assert_allclose(task.compute_jacobian(conf), fd_jacobian(task, conf), atol=2e-6)


def test_relative_error_ignores_the_floating_base():
    conf = random_configuration(5)
    task = RelativeFrameTask("left_rubber_hand", "torso_link")
    task.set_target_from_configuration(conf)
    moved = conf.q.copy()
    moved[:3] += [1.0, -2.0, 0.5]
    conf.update(moved)
    np.testing.assert_allclose(task.compute_error(conf), 0.0, atol=1e-12)


def test_same_frame_twice_is_refused():
    with pytest.raises(TaskDefinitionError, match="two different frames"):
        RelativeFrameTask("pelvis", "pelvis")
