"""The emulator's gantry must not destabilise the hanging robot: its roll/pitch damper acts on the
light pelvis (~0.009 kg m^2), which an explicit damper at 2 ms made flip +-40 rad/s every step while
the motors damped (the host's over-speed check then tripped at random in sim2sim runs)."""

import numpy as np

from g1_control.robot import g1
from g1_control.sim.emulator import Gantry
from g1_control.sim.mujoco_backend import MujocoBackend, MujocoConfig
from g1_control.types import MotorCommand


def test_a_damped_robot_hanging_in_the_gantry_stays_slow():
    mujoco = MujocoBackend(MujocoConfig(lockstep=True, hard_joint_stops=True))  # as g1 sim-robot builds it
    gantry = Gantry(mujoco, physics_dt_s=mujoco.config.physics_dt_s, lower_on_policy=True)
    gantry.reset()
    damping = MotorCommand.damping(g1.KD_DEFAULT)
    limp = MotorCommand(q_rad=np.zeros(g1.NUM_JOINTS), kp=np.zeros(g1.NUM_JOINTS), kd=np.zeros(g1.NUM_JOINTS))
    worst, past = 0.0, np.zeros(g1.NUM_JOINTS)
    for command, seconds in ((damping, 1.0), (limp, 0.5)):
        for _ in range(round(seconds / 0.002)):
            gantry.write_command(command)
            gantry.step(0.002)
            state = gantry.read_state()
            worst = max(worst, float(np.max(np.abs(state.dq_radps) / g1.VELOCITY_LIMIT_RADPS)))
            past = np.maximum(past, np.maximum(g1.Q_MIN_RAD - state.q_rad, state.q_rad - g1.Q_MAX_RAD))
    assert worst < 0.5, f"a joint reached {worst:.2f} of its velocity limit"
    # the torso falls onto its waist stops, which hold (MuJoCo's default soft limits let waist roll 0.030 rad past, beyond the preflight's 0.02)
    assert np.max(past) < 0.005, f"{g1.JOINT_NAMES[int(np.argmax(past))]} went {np.max(past):.4f} rad past its stop"
    assert state.base_pos_w_m is not None and state.base_pos_w_m[2] > 0.6  # still hanging
