"""Acceleration tasks and the model's drift terms."""

import numpy as np
import pytest

from g1_control.errors import WbcConfigError
from g1_control.robot import description, g1
from g1_control.robot.dynamics import WbcModel
from g1_control.trackers.wbc.tasks import TaskGains, orientation_task, posture_task, rotation_error


def rot_z(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def test_rotation_error_is_the_world_rotation_vector():
    np.testing.assert_allclose(rotation_error(rot_z(0.3), np.eye(3)), [0, 0, 0.3], atol=1e-12)
    np.testing.assert_allclose(rotation_error(np.eye(3), rot_z(0.3)), [0, 0, -0.3], atol=1e-12)
    np.testing.assert_allclose(rotation_error(rot_z(3.0), rot_z(0.5)), [0, 0, 2.5], atol=1e-9)
    assert np.linalg.norm(rotation_error(rot_z(np.pi), np.eye(3))) == pytest.approx(np.pi)


def test_posture_task_is_a_pd_on_the_joints():
    q = np.zeros(29)
    task = posture_task(35, q, np.ones(29), np.full(29, 0.1), np.zeros(29), TaskGains(100, 20, 2))
    np.testing.assert_allclose(task.target, 100 * 0.1 - 20 * 1.0)
    assert task.jac.shape == (29, 35) and np.all(task.jac[:, :6] == 0) and np.all(task.weight == 2)


def test_orientation_task_drives_toward_the_reference():
    task = orientation_task("o", np.eye(3, 35), np.zeros(3), np.eye(3), np.zeros(3), rot_z(0.1), np.zeros(3),
                            TaskGains(100, 20, 1))
    assert task.target[2] == pytest.approx(10.0)


def test_critically_damped_gains_and_validation():
    g = TaskGains.critically_damped(1.0, 3.0)
    assert g.kd**2 == pytest.approx(4 * g.kp)
    with pytest.raises(WbcConfigError, match="kp, kd, weight >= 0"):
        TaskGains(-1.0, 0.0, 1.0)


def test_model_drift_matches_finite_differences_of_the_frame_velocity():
    """J_dot v from the model equals d/dt (J v) along the motion with zero acceleration."""
    import pinocchio as pin

    rng = np.random.default_rng(1)
    m = WbcModel()
    q = description.pinocchio_q(np.array([0.1, 0.0, 0.75]), np.array([0.99, 0.05, 0.1, 0.0]) / np.linalg.norm([0.99, 0.05, 0.1, 0]),
                                g1.DEFAULT_Q_RAD)
    v = rng.normal(scale=0.5, size=m.nv)
    m.update(q, v)
    fid = m.hand_ids[1]
    f0 = m.frame(fid)
    com_vel0, com_drift = m.com_vel_mps.copy(), m.com_drift.copy()
    dt = 1e-6
    m.update(pin.integrate(m.model, q, v * dt), v)
    f1 = m.frame(fid)
    np.testing.assert_allclose((f1.vel_w - f0.vel_w) / dt, f0.drift_w, rtol=1e-3, atol=1e-3)
    np.testing.assert_allclose((m.com_vel_mps - com_vel0) / dt, com_drift, rtol=1e-3, atol=1e-3)
