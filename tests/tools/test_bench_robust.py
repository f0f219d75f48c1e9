"""`g1 bench robust` on a tiny configuration (not timed): a row runs on the drawn robot and measures
from ground truth; the summary, the JSON and the exit code on a fall."""

import json
import math
from types import SimpleNamespace

import pytest

from g1_control.tools import bench_robust as B


def test_a_row_runs_on_the_drawn_robot_and_measures_ground_truth():
    (nominal, drawn) = B.run_rows([None, 2], walk_s=5.0, only=["ppo"], echo=lambda line: None)
    assert (nominal.seed, drawn.seed) == (None, 2)
    assert nominal.draw == "MujocoBackend"
    assert drawn.draw.startswith("MujocoBackend randomised (seed 2: ")
    for row in (nominal, drawn):
        assert not row.fell and row.min_pelvis_m > 0.55
        assert 0.35 < row.achieved[0] < 0.75, row  # commanded 0.6; ground truth over whole gait cycles
    assert nominal.achieved != drawn.achieved


def _row(controller, seed, vx=0.55, fell=False, step=None):
    return B.RobustRow(controller, "step" if step is not None else "forward_0.6", seed, command_vx_mps=0.6,
                       achieved=[vx, 0.0, 0.0] if not fell else [math.nan] * 3, fell=fell, step_done=step)


def test_the_summary_counts_falls_and_speeds_of_randomised_draws_only():
    rows = [_row("wbc", None, 0.61), _row("wbc", 0, 0.5), _row("wbc", 1, fell=True), _row("ppo", 0, 0.58),
            _row("layer", 0, step=True), _row("layer", 1, step=False)]
    lines = B.summary(rows)
    assert lines[0].startswith("  wbc: 1 falls in 2 randomised draws; achieved vx 0.500 m/s mean (0.500..0.500) "
                               "for 0.6 commanded = 83 %; nominal robot 0.610 m/s")
    assert lines[1].startswith("  ppo: 0 falls in 1 randomised draws")
    assert "step up and down done 1/2; failed on s1 (friction " in lines[2]
    assert [r.failed for r in rows] == [False, False, True, False, False, True]


def test_the_summary_names_the_draws_a_row_failed_on_with_their_friction_and_latency():
    friction, latency = B.draw_friction_latency(25)
    assert 0.5 <= friction <= 1.2 and 0.005 <= latency <= 0.015
    # the draw's own values, whatever the variant's bodies (they are drawn first)
    from g1_control.sim.randomize import RandomizeConfig, draw
    full = draw(RandomizeConfig(seed=25), tuple(f"b{i}" for i in range(30)), 29)
    assert (full.foot_friction, full.latency_s) == (friction, latency)
    lines = B.summary([_row("wbc23", None, 0.6), _row("wbc23", 25, fell=True), _row("wbc23", 26, 0.55)])
    assert lines == [f"  wbc23: 1 falls in 2 randomised draws; achieved vx 0.550 m/s mean (0.550..0.550) for 0.6 "
                     f"commanded = 92 %; nominal robot 0.600 m/s; failed on s25 (friction {friction:.2f}, "
                     f"latency {1000 * latency:.1f} ms)"]


def test_the_wbc23_row_walks_the_23_dof_robot_the_controller_models(monkeypatch):
    from g1_control.launch import builder

    built = []

    def spy(launch, *args, **kwargs):
        loop = builder_build(launch, *args, **kwargs)
        built.append((launch.backend.expected_variant, loop.backend.model.nu, loop.tracker.dyn.dynamics_model.nv - 6))
        return loop

    builder_build = builder.build_loop
    monkeypatch.setattr(builder, "build_loop", spy)
    (row,) = B.run_rows([None], walk_s=4.0, only=["wbc23"], echo=lambda line: None)
    assert built == [("g1_23dof", 23, 23)]
    assert row.controller == "wbc23" and not row.fell and row.min_pelvis_m > 0.55
    assert 0.4 < row.achieved[0] < 0.75, row  # commanded 0.6, ground truth


@pytest.mark.parametrize(("fell", "code"), [(False, 0), (True, 1)])
def test_a_fall_makes_the_bench_exit_1_and_is_in_the_json(tmp_path, monkeypatch, fell, code):
    monkeypatch.setattr(B, "run_rows", lambda seeds, walk_s, only, echo: [_row("wbc", s, fell=fell and s == 1)
                                                                         for s in seeds])
    out = tmp_path / "robust.json"
    assert B.main(SimpleNamespace(seconds=5.0, only="wbc", json=str(out), draws=2, seed=0)) == code
    data = json.loads(out.read_text())
    assert [r["seed"] for r in data["rows"]] == [None, 0, 1]
    assert [r["fell"] for r in data["rows"]] == [False, False, fell]
    assert data["randomize"]["latency_s"] == [0.005, 0.015]
