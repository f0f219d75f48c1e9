"""The robot path against a randomised robot: `g1 sim-robot --randomize SEED` applies the draw in its
MuJoCo behind DDS (the torque a motor gives over the wire is the drawn fraction of the command; the
model's mass is the draw's), and `g1 deploy` walks it.

Thresholds are loose (shared 2-core host)."""

from __future__ import annotations

import time

import numpy as np
import pytest
from deploy_test_helpers import deploy_to_the_end
from test_deploy_sim2sim import Emulator

from g1_control.hardware.dds_backend import UnitreeDDSBackend
from g1_control.robot import g1
from g1_control.sim.mujoco_backend import MujocoBackend, MujocoConfig
from g1_control.sim.randomize import RandomizeConfig
from g1_control.types import MotorCommand
from tests.paths import LAUNCH_DIR

pytestmark = pytest.mark.timing

SEED = 3


def _robot_mass(sim: MujocoBackend) -> float:
    m = sim.model
    robot = m.body(g1.BASE_BODY).id
    return float(sum(m.body_mass[b] for b in range(1, m.nbody) if m.body_rootid[b] == robot))


def test_the_emulated_robot_runs_with_the_draw_of_its_seed(partition):
    here = MujocoBackend(MujocoConfig(randomize=RandomizeConfig(seed=SEED)))
    assert here.draw is not None
    robot = Emulator(partition, "--gantry", "--randomize", str(SEED), "--rt-priority", "0")
    try:
        with UnitreeDDSBackend("lo", 1, partition=partition, connect_timeout_s=5.0, motion_service_timeout_s=5.0,
                               expected_mode_machine=5) as host:
            host.reset()
            # feed-forward torque only: each motor's output is its drawn strength times the command
            host.write_command(MotorCommand(tau_nm=np.full(g1.NUM_JOINTS, 2.0)))
            time.sleep(0.5)
            tau = host.read_state().tau_nm
        wire = robot.ask("report")
    finally:
        robot.close()
    np.testing.assert_allclose(tau, 2.0 * here.draw.motor_strength, atol=1e-4)  # LowState_ is float32
    assert tau.min() < 1.9, "weaker motors than the nominal robot's"
    drawn = wire["randomize"]
    assert drawn["seed"] == SEED and drawn["describe"] == here.describe()
    assert drawn["latency_applied_s"] == pytest.approx(here.latency_s)
    assert drawn["robot_mass_kg"] == pytest.approx(_robot_mass(here))
    assert abs(drawn["robot_mass_kg"] - _robot_mass(MujocoBackend())) > 0.05
    assert "randomised (seed 3: " in robot.stderr


def test_deploy_walks_a_randomised_robot(tmp_path, partition):
    _, wire = deploy_to_the_end(partition, LAUNCH_DIR / "sim2sim.yaml", tmp_path / "deploy.json", tmp_path,
                                emulator_flags=("--lower-gantry-on-policy", "--randomize", str(SEED)),
                                deploy_flags=("--duration", "5"),
                                waits=((r"zero torque: the robot is limp", 90),
                                       (r"control -> damping: control time over", 60)))
    assert wire["randomize"]["seed"] == SEED
    lowered, damped = wire["gantry_lowered_base_pos_w_m"], wire["first_damping_base_pos_w_m"]
    walked_m = damped[0] - lowered[0]
    print(f"\nsim2sim on randomised robot s{SEED} ({wire['randomize']['describe']}): walked {walked_m:.2f} m")
    assert walked_m > 1.0, "forward progress under the policy"
    assert damped[2] > 0.6, "still standing when control ended"
    assert wire["last_command_is_damping"] is True
