"""g1 bench execution at small scale: a seeded case or two of each behaviour, in physics, judged
from ground truth (the full suite is the bench)."""

from argparse import Namespace

import pytest

from g1_control.tools import bench_execution as bench
from g1_control.tools.physics_trials import Push, Trial, run_trial, walk_timeline


def _row(name):
    return next(b for b in bench.behaviours() if b.name == name)


@pytest.mark.parametrize("name", ["walk.carry.vx0.5", "walk.reach_up.vy0.2", "walk.wave.vx0.4+wz0.3"])
def test_styled_walking_meets_its_goal(name):
    row = bench.run_behaviour(_row(name))
    assert row.falls == 0
    assert row.met, f"{name}: {row.notes} err {row.velocity_error_pct} drift {row.drift} ub {row.upper_body_rms_rad}"
    assert row.velocity_error_pct <= 15.0 and row.upper_body_rms_rad <= 0.1


def test_crouch_walk_holds_the_planned_pelvis_height():
    row = bench.run_behaviour(_row("crouch_walk.0.65m.vx0.3"))
    assert row.met and row.falls == 0, row.notes


def test_pushes_from_each_direction_are_survived():
    # One seeded push per direction: standing from the front and back, walking from the sides.
    stand = bench.push_trials(False, seed=0)
    walk = bench.push_trials(True, seed=0)
    trials = [stand[0], stand[bench.PUSH_PHASES], walk[2 * bench.PUSH_PHASES], walk[3 * bench.PUSH_PHASES]]
    for trial in trials:
        result = run_trial(trial)
        assert not result.fell, f"{trial.name}: {result.fall}"
        # the push happened: the pelvis moved in its direction during it
        push = trial.pushes[0]
        t = result.log["t_s"]
        during = (t > push.t_s) & (t < push.t_s + push.duration_s + 0.1)
        v = result.log["velocity_true"][during, :2].mean(axis=0)
        direction = push.force_h_n[:2]
        assert v @ direction / (direction[0] ** 2 + direction[1] ** 2) ** 0.5 > 0.1


def test_the_bench_exits_nonzero_when_a_trial_falls(monkeypatch, tmp_path):
    shove = bench.Behaviour(
        "shove", "survive a 600 N push", lambda seed: [Trial("shove", walk_timeline("default", (0.0, 0.0, 0.0), walk_s=3.0),
                                                             pushes=[Push(1.5, (-600.0, 0.0, 0.0), 0.3)])],
        bench.judge_survive)
    monkeypatch.setattr(bench, "behaviours", lambda: [shove])
    code = bench.main(Namespace(only=None, seed=0, video=None, json=str(tmp_path / "out.json")))
    assert code == 1
    assert '"falls": 1' in (tmp_path / "out.json").read_text()
