import numpy as np

from g1_control.robot import g1
from g1_control.sim.motor_law import motor_torque
from g1_control.sim.mujoco_backend import MujocoBackend
from g1_control.types import MotorCommand


def test_reset_stands_on_the_floor_with_the_imu_upright():
    backend = MujocoBackend()
    state = backend.reset()
    assert 0.7 < state.base_pos_w_m[2] < 0.85
    np.testing.assert_allclose(state.q_rad, g1.DEFAULT_Q_RAD)
    np.testing.assert_allclose(state.imu_quat_wxyz, [1, 0, 0, 0], atol=1e-9)
    state.validate()


def test_applied_torque_is_the_motor_law():
    backend = MujocoBackend()
    backend.reset()
    cmd = MotorCommand(q_rad=g1.DEFAULT_Q_RAD + 0.3, kp=g1.KP_DEFAULT, kd=g1.KD_DEFAULT, tau_nm=np.full(29, 0.2))
    backend.write_command(cmd)
    before = backend.read_state()
    expected = motor_torque(cmd, before.q_rad, before.dq_radps)
    backend.step(backend.model.opt.timestep)  # exactly one physics step
    np.testing.assert_allclose(backend.read_state().tau_nm, expected)
    np.testing.assert_allclose(backend.data.actuator_force, expected)


def test_lockstep_is_deterministic():
    def rollout():
        backend = MujocoBackend()
        backend.reset()
        backend.write_command(MotorCommand(q_rad=g1.DEFAULT_Q_RAD, kp=g1.KP_DEFAULT, kd=g1.KD_DEFAULT))
        for _ in range(100):
            backend.step(0.002)
        return backend.read_state()

    a, b = rollout(), rollout()
    np.testing.assert_array_equal(a.q_rad, b.q_rad)
    np.testing.assert_array_equal(a.base_pos_w_m, b.base_pos_w_m)


def test_imu_reports_gravity_and_rotation():
    backend = MujocoBackend()
    backend.reset(yaw_rad=0.5)  # 2 mm above the floor: free fall reads zero specific force
    backend.step(0.004)
    assert np.linalg.norm(backend.read_state().imu_acc_mps2) < 0.5
    backend.step(0.2)  # landed, held by the default PD
    s = backend.read_state()
    assert 9.0 < s.imu_acc_mps2[2] < 10.6  # specific force of standing: up
    w, z = s.imu_quat_wxyz[0], s.imu_quat_wxyz[3]
    assert abs(2 * np.arctan2(z, w) - 0.5) < 0.05


def test_close_leaves_the_robot_damped():
    backend = MujocoBackend()
    backend.reset()
    backend.close()
    assert np.all(backend._command.kp == 0) and np.all(backend._command.kd > 0)
