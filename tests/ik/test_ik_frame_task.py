import numpy as np
import pinocchio as pin
import pytest

from g1_control.ik.configuration import Configuration
from g1_control.ik.exceptions import InvalidFrameError, TaskDefinitionError
from g1_control.ik.tasks import FrameTask, pose_from_vector
from g1_control.robot import description, g1


def random_configuration(seed: int) -> Configuration:
    rng = np.random.default_rng(seed)
    joints = rng.uniform(g1.Q_MIN_RAD * 0.5, g1.Q_MAX_RAD * 0.5)
    quat = rng.standard_normal(4)
    quat /= np.linalg.norm(quat)
    return Configuration(description.pinocchio_q(rng.standard_normal(3), quat, joints))


def fd_jacobian(task, conf: Configuration, eps: float = 1e-6) -> np.ndarray:
    q0 = conf.q.copy()
    cols = []
    for i in range(conf.nv):
        step = np.zeros(conf.nv)
        step[i] = eps
        conf.update(pin.integrate(conf.model, q0, step))
        plus = task.compute_error(conf).copy()
        conf.update(pin.integrate(conf.model, q0, -step))
        minus = task.compute_error(conf).copy()
        cols.append((plus - minus) / (2 * eps))
    conf.update(q0)
    return np.array(cols).T


@pytest.mark.parametrize("frame", ["left_rubber_hand", "pelvis", "right_toe", "torso_link"])
def test_frame_task_jacobian_matches_finite_differences(frame):
    conf = random_configuration(1)
    task = FrameTask(frame, 1.0, 1.0)
    target = pin.SE3(pin.utils.rpyToMatrix(0.3, -0.2, 0.5), np.array([0.2, -0.1, 0.5]))
    task.set_target(target)
    np.testing.assert_allclose(task.compute_jacobian(conf), fd_jacobian(task, conf), atol=2e-6)


def test_frame_task_error_is_zero_at_its_own_pose_and_grows_with_offset():
    conf = random_configuration(2)
    task = FrameTask("left_rubber_hand")
    task.set_target_from_configuration(conf)
    np.testing.assert_allclose(task.compute_error(conf), 0.0, atol=1e-12)
    task.set_target_position(task.target.translation + np.array([0.1, 0.0, 0.0]))
    np.testing.assert_allclose(task.compute_error(conf)[:3], [-0.1, 0.0, 0.0], atol=1e-12)


def test_position_only_task_has_zero_orientation_rows():
    conf = random_configuration(3)
    task = FrameTask("left_rubber_hand", 1.0, 0.0)
    task.set_target(pin.SE3.Identity())
    assert np.all(task.compute_jacobian(conf)[3:] == 0.0)


def test_bad_cost_shape_is_refused_with_the_shapes_expected():
    with pytest.raises(TaskDefinitionError) as err:
        FrameTask("pelvis", position_cost=np.ones(2))
    assert str(err.value) == ("FrameTask('pelvis') position cost must be a scalar or a vector of shape (1,) or (3,). "
                              "Got (2,)")


def test_negative_cost_and_bad_gain_are_refused():
    with pytest.raises(TaskDefinitionError, match=">= 0"):
        FrameTask("pelvis", position_cost=-1.0)
    with pytest.raises(TaskDefinitionError, match="gain must be in"):
        FrameTask("pelvis", gain=2.0)


def test_unknown_frame_is_named():
    conf = Configuration()
    task = FrameTask("left_hoof")
    task.set_target(pin.SE3.Identity())
    with pytest.raises(InvalidFrameError, match="no frame 'left_hoof'"):
        task.compute_error(conf)


def test_task_without_target_says_so():
    with pytest.raises(TaskDefinitionError, match="has no target"):
        FrameTask("pelvis").compute_error(Configuration())


def test_pose_from_vector_checks_layout():
    pose = pose_from_vector(np.array([1.0, 2.0, 3.0, 0.0, 0.0, 0.0, 2.0]))
    np.testing.assert_allclose(pose.rotation, pin.utils.rpyToMatrix(0, 0, np.pi), atol=1e-12)
    with pytest.raises(TaskDefinitionError, match="7 finite numbers"):
        pose_from_vector(np.zeros(6))
    with pytest.raises(TaskDefinitionError, match="quaternion is zero"):
        pose_from_vector(np.zeros(7))


def test_stacked_frame_tasks_give_the_same_rows_as_each_task():
    from g1_control.ik.tasks.frame_task import stack_frame_tasks

    conf = random_configuration(13)
    tasks = [FrameTask("left_rubber_hand", 2.0, 0.5, gain=0.5), FrameTask("right_toe", 3.0, 0.0),
             FrameTask("torso_link", 0.0, 1.5)]
    for i, t in enumerate(tasks):
        t.set_target(pin.SE3(pin.utils.rpyToMatrix(0.1 * i, 0.2, -0.3), np.array([0.1, 0.2 * i, 0.4])))
    jac, err, w2 = stack_frame_tasks(conf, tasks)
    rows = [slice(0, 6), slice(6, 9), slice(9, 15)]
    for task, r in zip(tasks, rows):
        e, j = task.compute_error_and_jacobian(conf)
        keep = slice(0, 6) if task._track_orientation else slice(0, 3)
        np.testing.assert_allclose(jac[r], j[keep], atol=1e-12)
        np.testing.assert_allclose(err[r], task.gain * e[keep], atol=1e-12)
        np.testing.assert_allclose(w2[r], task.cost[keep] ** 2)
