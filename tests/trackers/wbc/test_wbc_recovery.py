"""Pushed while walking, the whole-body controller's recovery steps (gait.py's GaitTargets.recovery,
WbcConfig.recovery_swing_weight) keep it up: two pushes of `g1 bench locomotion`'s grid (150 N for
0.2 s from the front, walking 0.5 m/s) in lockstep MuJoCo through the one loop builder, judged from
the simulator's pelvis height. With the swing foot held at its plain walking weight in recovery
steps, the QP swings the leg back instead of stepping and the robot falls in push_front_3 (so the
test goes red; push_front_4 fell too while recovery steps swung at least 0.2 s).
Chaotic near its limits, the controller survives only some of the grid; these are survived. Two more
(front_1, right_4) are survived because a recovery step may land after a swing of only
GaitConfig.min_swing_s (0.15 s; at 0.2 both fell)."""

import functools

import pytest

from g1_control.tools import bench_locomotion as bench
from g1_control.trackers.wbc import tracker as wbc_tracker
from g1_control.trackers.wbc.gait import GaitConfig

UPRIGHT_PELVIS_M = 0.6
"""Ground-truth pelvis height the robot stays above (it walks at ~0.68 m; a fall ends at 0.4)."""
CASES = ("push_front_3", "push_front_4")
QUICK_CASES = ("push_front_1", "push_right_4")
"""Survived only with the quicker recovery steps (GaitConfig.min_swing_s 0.15, not 0.2)."""


def run_push(name: str):
    case = next(c for c in bench.push_cases() if c.name == name)
    return bench.run_case("wbc", case, walk_s=0.0)


@pytest.mark.parametrize("name", CASES + QUICK_CASES)
def test_recovery_steps_survive_a_push(name):
    row = run_push(name)
    assert not row.fell and not row.trip, f"{name}: {row.fall or row.trip}"
    assert row.pushes_survived == row.pushes == 1
    assert row.min_pelvis_m > UPRIGHT_PELVIS_M


def test_without_the_recovery_swing_weight_push_front_3_fell(monkeypatch):
    plain = wbc_tracker.WbcConfig().swing_foot.weight
    monkeypatch.setattr(wbc_tracker, "WbcConfig", functools.partial(wbc_tracker.WbcConfig, recovery_swing_weight=plain))
    rows = [run_push("push_front_3")]
    assert all(row.min_pelvis_m < UPRIGHT_PELVIS_M for row in rows), [(r.case, r.min_pelvis_m) for r in rows]


def test_with_a_longer_minimum_swing_the_quick_cases_fell(monkeypatch):
    slow = GaitConfig(min_swing_s=0.2)
    monkeypatch.setattr(wbc_tracker, "WbcConfig", functools.partial(wbc_tracker.WbcConfig, gait=slow))
    rows = [run_push(name) for name in QUICK_CASES]
    assert all(not row.pushes_survived for row in rows), [(r.case, r.pushes_survived, r.trip) for r in rows]
