"""backend.randomize: the loop a launch file builds runs on the randomised robot it names (the same
seed, the same robot and the same run; no section, the nominal robot), and the check line says so."""

from __future__ import annotations

import numpy as np

from g1_control.cli.main import main
from g1_control.launch.builder import build_loop
from g1_control.launch.schema import load_launch
from g1_control.sim.mujoco_backend import MujocoBackend
from tests.paths import LAUNCH_DIR

WALK = LAUNCH_DIR / "sim_walk.yaml"


def _walk(overrides: list[str], seconds: float = 2.5):
    loop = build_loop(load_launch(WALK, [*overrides, "input.timeline[0].duration_s=0.5"]))
    loop.reset()
    loop.run(seconds)
    sim = loop.backend
    assert isinstance(sim, MujocoBackend)
    return loop, sim, sim.data.qpos.copy()


def test_the_loop_runs_on_the_drawn_robot_and_the_same_seed_repeats_the_run():
    loop, sim, q = _walk(["backend.randomize.seed=4"])
    _, _, q_again = _walk(["backend.randomize.seed=4"])
    _, nominal, q_nominal = _walk([])
    assert sim.draw is not None and sim.draw.seed == 4 and nominal.draw is None
    assert loop.chain["backend"].startswith("MujocoBackend randomised (seed 4: ")
    assert sim.latency_s > 0 and not np.array_equal(sim.model.body_mass, nominal.model.body_mass)
    np.testing.assert_array_equal(q, q_again)  # lockstep: the same robot, the same run
    assert np.abs(q - q_nominal).max() > 1e-3, "another robot walks differently"
    assert not loop.fell


def test_ranges_come_from_the_launch_file():
    _, sim, _ = _walk(["backend.randomize={seed: 1, latency_s: [0.02, 0.02], foot_friction: [0.9, 0.9]}"], 0.1)
    assert sim.latency_s == 0.02 and sim.draw is not None and sim.draw.foot_friction == 0.9


def test_the_check_line_names_the_seed(capsys):
    assert main(["launch", str(WALK), "--check", "--set", "backend.randomize.seed=5"]) == 0
    assert ", randomised (seed 5)," in capsys.readouterr().out
