import numpy as np

from g1_control.robot import g1
from g1_control.sim.motor_law import motor_torque
from g1_control.types import MotorCommand


def test_pd_plus_feedforward():
    rng = np.random.default_rng(1)
    q, dq = rng.normal(size=29) * 0.01, rng.normal(size=29) * 0.01
    cmd = MotorCommand(q_rad=q + 0.01, dq_radps=dq - 0.02, kp=np.full(29, 10.0), kd=np.full(29, 2.0),
                       tau_nm=np.full(29, 0.5))
    np.testing.assert_allclose(motor_torque(cmd, q, dq), 10.0 * 0.01 + 2.0 * -0.02 + 0.5)


def test_clipped_to_effort_limits_per_joint():
    cmd = MotorCommand(q_rad=np.full(29, 10.0), kp=np.full(29, 1000.0))
    tau = motor_torque(cmd, np.zeros(29), np.zeros(29))
    np.testing.assert_allclose(tau, g1.EFFORT_LIMIT_NM)
    cmd.q_rad[:] = -10.0
    np.testing.assert_allclose(motor_torque(cmd, np.zeros(29), np.zeros(29)), -g1.EFFORT_LIMIT_NM)


def test_disabled_motor_gives_no_torque():
    cmd = MotorCommand(q_rad=np.ones(29), kp=np.full(29, 5.0))
    cmd.enable[3] = False
    tau = motor_torque(cmd, np.zeros(29), np.zeros(29))
    assert tau[3] == 0.0 and tau[2] == 5.0


def test_damping_command_opposes_motion():
    tau = motor_torque(MotorCommand.damping(3.0), np.zeros(29), np.full(29, 0.5))
    np.testing.assert_allclose(tau, -1.5)
