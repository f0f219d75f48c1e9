"""How `g1 bench execution` turns trial verdicts into a row (no physics: run_trial replaced by
stand-in results with known figures; the physics is tests/tools/test_execution_suite.py)."""

from types import SimpleNamespace

import pytest

from g1_control.report.verdict import Verdict
from g1_control.tools import bench_execution as bench
from g1_control.tools import execution_goals as goals


def _result(**kw):
    base = dict(fell=False, fall=None, goals=[], sim_s=10.0, wall_s=2.0, layer_cpu=None, log=None, trial=None)
    return SimpleNamespace(**{**base, **kw})


def _row(behaviour, results, monkeypatch):
    results = iter(results)
    monkeypatch.setattr(bench, "run_trial", lambda trial, **kw: next(results))
    return bench.run_behaviour(behaviour)


def test_a_walk_row_takes_its_figures_from_the_verdicts(monkeypatch):
    walk = next(b for b in bench.behaviours() if b.name == "walk.default.vx0.5")
    ok = _result(velocity=lambda i: (0.47, 0.02, 0.0), upper_body_rms=lambda i: 0.05)
    verdict = walk.judge(ok)
    assert isinstance(verdict, Verdict) and verdict.ok
    assert verdict.values == pytest.approx({"velocity_error_pct": 6.0, "drift": 0.02, "upper_body_rms_rad": 0.05})
    row = _row(walk, [ok], monkeypatch)
    assert (row.trials, row.successes, row.falls, row.met) == (1, 1, 0, True)
    assert (row.velocity_error_pct, row.drift, row.upper_body_rms_rad) == pytest.approx((6.0, 0.02, 0.05))
    assert row.hand_error_m is None and row.object_error_m is None
    assert row.real_time_factor == 5.0
    assert row.notes == ["walk default vx0.5: v (+0.47, +0.02, +0.00)"]  # one trial: its note is shown
    fell = _result(fell=True, fall="tilt at 3.1 s")
    row = _row(walk, [fell], monkeypatch)
    assert (row.successes, row.falls, row.met, row.velocity_error_pct) == (0, 1, False, None)
    assert row.notes == ["walk default vx0.5: fell: tilt at 3.1 s"]


def test_goal_rows_count_goals_and_take_hand_and_object_errors(monkeypatch):
    rows = {b.name: b for b in goals.goal_behaviours(bench.Behaviour)}
    reaches = [{"kind": "reach", "status": "reached", "within_tolerance": 1.0, "hand_error_mean_m": 0.01}] * 19
    reaches.append({"kind": "reach", "status": "timed_out", "within_tolerance": 0.2, "hand_error_mean_m": 0.05,
                    "message": "out of reach"})
    reach = rows["reach.left"]
    verdict = reach.judge(_result(goals=reaches))
    assert (verdict.ok, verdict.count, verdict.successes, verdict.met()) == (True, 20, 19, 19)
    assert verdict.values == pytest.approx({"hand_error_m": 0.012})
    assert verdict.text == "19/20 points; missed 19: out of reach"
    box = rows["box.table"]
    placed = [{"kind": "pick", "status": "reached"}, {"kind": "place", "status": "reached", "place_error_xy_m": 0.04}]
    verdict = box.judge(_result(goals=placed))
    assert (verdict.ok, verdict.values, verdict.text) == (True, {"object_error_m": 0.04}, "placed 4.0 cm off")
    verdict = box.judge(_result(goals=placed[:1]))
    assert (verdict.ok, verdict.values) == (False, {})  # not placed: no object error to report
    trials = box.trials(0)
    assert len(trials) >= 3
    results = [_result(goals=placed)] * (len(trials) - 1) + [_result(goals=placed[:1])]
    row = _row(box, results, monkeypatch)
    assert (row.trials, row.successes, row.object_error_m, row.hand_error_m) == (len(trials), len(trials) - 1, 0.04, None)
    assert row.notes == [f"{trials[-1].name}: place not started: "]  # several trials: the misses' notes only
