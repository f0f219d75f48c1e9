"""MuJoCo's actuators apply g1_control/sim/motor_law.py: the same torques on random states and
commands (clipping and disabled motors included), and the same walk as the law evaluated in Python
at every physics step (the backend as it was before the law moved into the model)."""

import mujoco
import numpy as np
import pytest

from g1_control.launch.builder import build_loop
from g1_control.launch.schema import LaunchFile, Segment
from g1_control.robot import description, g1
from g1_control.sim.motor_law import motor_torque
from g1_control.sim.mujoco_backend import MujocoBackend
from g1_control.sim.scene import grip_physics
from g1_control.types import MotorCommand


class PythonLawBackend(MujocoBackend):
    """The reference: plain motor actuators (ctrl = torque) on the scene as robot/description.py
    builds it (implicitfast integrator), with the backend's floor friction (elliptic cones, scene.py
    grip_physics), the torque computed by motor_law.py before every step."""

    def __init__(self):
        self._tau = np.zeros(g1.NUM_JOINTS)
        super().__init__()

    def _compile(self):
        spec = description.mujoco_spec(timestep_s=self.config.physics_dt_s)
        grip_physics(spec)
        return spec.compile()

    def write_command(self, command):
        self._command = command

    def step_ticks(self, command, dt_s, n):
        for _ in range(n):
            self.write_command(command)
            self.step(dt_s)

    def _physics_steps(self, n):
        d = self.data
        for _ in range(n):
            motor_torque(self._command, d.qpos[7:], d.qvel[6:], out=self._tau)
            d.ctrl[:] = self._tau
            mujoco.mj_step(self.model, d)
        self._tick += n

    def read_state(self):
        state = super().read_state()
        state.tau_nm = self._tau.copy()
        return state


def _random_command(rng, scale=1.0):
    n = g1.NUM_JOINTS
    cmd = MotorCommand(q_rad=g1.DEFAULT_Q_RAD + rng.normal(scale=0.5 * scale, size=n),
                       dq_radps=rng.normal(scale=2.0 * scale, size=n),
                       kp=rng.uniform(0.0, 300.0, size=n), kd=rng.uniform(0.0, 10.0, size=n),
                       tau_nm=rng.normal(scale=20.0 * scale, size=n), enable=rng.random(n) > 0.1)
    return cmd


def test_actuator_forces_are_the_motor_law_on_random_states_and_commands():
    backend = MujocoBackend()
    backend.reset()
    m, d = backend.model, backend.data
    rng = np.random.default_rng(7)
    clipped = disabled = 0
    for trial in range(200):
        d.qpos[7:] = g1.DEFAULT_Q_RAD + rng.normal(scale=0.4, size=g1.NUM_JOINTS)
        d.qvel[6:] = rng.normal(scale=3.0, size=g1.NUM_JOINTS)
        cmd = _random_command(rng, scale=1.0 + trial / 20)  # later trials mostly saturate
        backend.write_command(cmd)
        mujoco.mj_forward(m, d)
        expected = motor_torque(cmd, d.qpos[7:].copy(), d.qvel[6:].copy())
        np.testing.assert_allclose(d.actuator_force, expected, rtol=0, atol=1e-9)
        clipped += int(np.sum(np.abs(expected) == g1.EFFORT_LIMIT_NM))
        disabled += int(np.sum(~cmd.enable))
    assert clipped > 500 and disabled > 200  # both regimes were exercised


def test_joint_limits_and_effort_limits_are_the_robot_s():
    m = MujocoBackend().model
    np.testing.assert_array_equal(m.actuator_forcerange[:, 1], g1.EFFORT_LIMIT_NM)
    np.testing.assert_array_equal(m.actuator_forcerange[:, 0], -g1.EFFORT_LIMIT_NM)
    assert m.actuator_forcelimited.all() and not m.actuator_ctrllimited.any()
    # The law acts on the joint each actuator names, in the robot's joint order.
    for i, name in enumerate(g1.JOINT_NAMES):
        assert m.joint(m.actuator_trnid[i, 0]).name == name


def test_the_command_is_taken_when_written():
    backend = MujocoBackend()
    backend.reset()
    cmd = MotorCommand(q_rad=g1.DEFAULT_Q_RAD.copy(), kp=g1.KP_DEFAULT.copy(), kd=g1.KD_DEFAULT.copy())
    backend.write_command(cmd)
    before = backend.model.actuator_biasprm.copy()
    cmd.kp[:] = 0.0  # changing the caller's arrays afterwards changes nothing
    np.testing.assert_array_equal(backend.model.actuator_biasprm, before)


def test_batched_ticks_equal_single_ticks_with_a_push_in_between():
    def run(batched):
        backend = MujocoBackend()
        backend.reset()
        cmd = MotorCommand(q_rad=g1.DEFAULT_Q_RAD.copy(), kp=g1.KP_DEFAULT.copy(), kd=g1.KD_DEFAULT.copy())
        backend.write_command(cmd)
        backend.step(0.01)
        backend.push([40.0, -20.0, 0.0], 0.013)  # ends inside the next batch, between physics steps
        if batched:
            backend.step_ticks(cmd, 0.002, 20)
        else:
            for _ in range(20):
                backend.write_command(cmd)
                backend.step(0.002)
        return backend.read_state(), backend.data.xfrc_applied.copy()

    (a, fa), (b, fb) = run(True), run(False)
    np.testing.assert_array_equal(a.q_rad, b.q_rad)
    np.testing.assert_array_equal(a.base_pos_w_m, b.base_pos_w_m)
    np.testing.assert_array_equal(fa, fb)
    assert a.tick == b.tick == 25
    assert not np.any(fa)  # the push is over and its force gone


def _walk(backend, seconds):
    launch = LaunchFile(name="motor_law_walk")
    launch.input.timeline = [Segment(0.3, label="stand"), Segment(seconds, vx_mps=0.5, wz_radps=0.3, label="walk")]
    launch.output.video = "off"
    loop = build_loop(launch, backend=backend)
    loop.reset()
    loop.run(0.3 + seconds)
    assert not loop.fell
    return loop.log.arrays()


@pytest.mark.slow
def test_a_second_of_walking_follows_the_python_law():
    new, ref = _walk(MujocoBackend(), 1.0), _walk(PythonLawBackend(), 1.0)
    assert np.ptp(ref["base_pos_m"][:, 0]) > 0.1  # it walked
    np.testing.assert_allclose(new["q_rad"], ref["q_rad"], rtol=0, atol=1e-5)
    np.testing.assert_allclose(new["base_pos_m"], ref["base_pos_m"], rtol=0, atol=1e-6)
    np.testing.assert_allclose(new["base_quat_wxyz"], ref["base_quat_wxyz"], rtol=0, atol=1e-6)
    # The logged torque is what the drivers applied on the last physics step before each tick.
    np.testing.assert_allclose(new["tau_nm"], ref["tau_nm"], rtol=0, atol=1e-2)
