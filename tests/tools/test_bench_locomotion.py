"""`g1 bench locomotion` on a tiny configuration (not timed): rows from ground truth for the WBC and
a walking policy, the JSON it writes, and its exit code on a fall."""

import json
from types import SimpleNamespace

import numpy as np
import pytest

from g1_control.tools import bench_locomotion as B


def test_rows_measure_what_the_robot_achieved():
    rows, (base50, base99) = B.run_table(["wbc", "ppo"], [B.Case("forward_0.4", (0.4, 0.0, 0.0))], walk_s=6.0,
                                         echo=lambda line: None)
    assert [r.name for r in rows] == ["wbc/forward_0.4", "ppo/forward_0.4"]
    for row in rows:
        assert not row.fell and row.min_pelvis_m > 0.55
        assert 0.25 < row.achieved[0] < 0.55, row  # from the simulator's ground truth
        assert row.error_pct == pytest.approx(100 * (row.achieved[0] - 0.4) / 0.4)
        assert row.off_axis == pytest.approx(max(abs(row.achieved[1]), abs(row.achieved[2])))
        assert 0 < row.act_cpu_p50_us <= row.act_cpu_p99_us
    # the WBC's act() costs more than the dynamics it evaluates; the baseline ran on its states
    assert 0 < base50 <= base99 and rows[0].act_cpu_p50_us > base50


def test_steady_velocity_averages_whole_cycles_only():
    t = np.arange(0.0, 10.0, 0.01)
    vel = np.zeros((len(t), 3))
    vel[:, 0] = 0.5 + 0.2 * np.sin(2 * np.pi * t / 0.7)  # a sway with the gait's period
    log = {"t_s": t, "velocity_true": vel}
    assert B.steady_velocity(log, 2.0, 10.0, 0.7)[0] == pytest.approx(0.5, abs=1e-3)
    with pytest.raises(ValueError, match="no whole gait cycle"):
        B.steady_velocity(log, 9.5, 10.0, 0.7)


def test_the_wbc_stride_is_its_cadence_at_the_command():
    """Walking fast the WBC's steps come quicker: the whole cycles the figures average over are
    its strides at the command's cadence, the slow one walking slowly."""
    from g1_control.trackers.wbc.gait import VelocityGait, step_duration_for

    tracker = SimpleNamespace(gait=VelocityGait())
    cfg = tracker.gait.config
    assert B.wbc_stride_s(tracker, (0.5, 0.0, 0.0)) == pytest.approx(2 * cfg.step_s)
    fast = B.wbc_stride_s(tracker, (0.0, 0.4, 0.0))
    assert fast == pytest.approx(2 * step_duration_for(cfg, np.array([0.0, 0.4]))) and fast < 2 * cfg.step_s - 0.05
    # beyond the gait's limits: the cadence of the speed it walks
    assert B.wbc_stride_s(tracker, (3.0, 0.0, 0.0)) == pytest.approx(
        2 * step_duration_for(cfg, tracker.gait.feasible(np.array([3.0, 0.0, 0.0]))[:2]))


def test_a_fall_makes_the_bench_exit_1_and_is_in_the_json(tmp_path, monkeypatch):
    # a 600 N shove from the side for half a second topples any of the controllers
    shove = B.Case("shove", (0.0, 0.0, 0.0), timeline=(B.Segment(4.0, label="stand"),),
                   pushes=((1.0, (0.0, 600.0, 0.0)),))
    monkeypatch.setattr(B, "CASES", (shove,))
    monkeypatch.setattr(B, "push_cases", lambda walk_s: ())
    monkeypatch.setattr(B, "random_cases", lambda: ())
    monkeypatch.setattr(B, "PUSH_S", 0.5)
    out = tmp_path / "loco.json"
    code = B.main(SimpleNamespace(seconds=3.0, only="wbc/", json=str(out)))
    assert code == 1
    data = json.loads(out.read_text())
    (row,) = data["rows"]
    assert row["controller"] == "wbc" and row["fell"] and row["min_pelvis_m"] < 0.45
    assert row["pushes"] == 1 and row["pushes_survived"] == 0


def test_the_push_grid_is_one_run_per_direction_and_point_of_the_stride():
    cases = B.push_cases()
    assert len(cases) == 4 * B.PUSH_PHASES
    assert {c.name.rsplit("_", 1)[0] for c in cases} == {"push_front", "push_back", "push_left", "push_right"}
    for case in cases:
        (t, force), = case.pushes
        assert t == B.PUSH_AT_S and np.linalg.norm(force) == B.PUSH_N
        assert sum(seg.duration_s for seg in case.timeline) >= t + 1.0 + B.PUSH_S + B.PUSH_SETTLE_S
    fractions = sorted({c.push_stride_fraction for c in cases})
    assert fractions == pytest.approx([k / B.PUSH_PHASES for k in range(B.PUSH_PHASES)])
