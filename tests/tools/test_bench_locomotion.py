"""`g1 bench locomotion` on a tiny configuration (not timed): rows from ground truth for the WBC and
a walking policy, the JSON it writes, and its exit code on a fall."""

import json
import os
import subprocess
import sys
from types import SimpleNamespace

import numpy as np
import pytest

from g1_control.tools import bench_locomotion as B
from tests.paths import REPO


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


# Two short lockstep rows of the WBC walking by its own gait: a walk with a turn (the gait's turned DCM
# offsets and its per-command speed limits) and a walk with a push on the pelvis from behind.
_TURN = B.Case("turn", (0.4, 0.0, 0.6), timeline=(B.Segment(0.5, label="stand"),
                                                  B.Segment(2.5, vx_mps=0.4, wz_radps=0.6, label="walk")))
_PUSH = B.Case("push", (0.5, 0.0, 0.0), timeline=(B.Segment(0.5, label="stand"),
                                                  B.Segment(2.5, vx_mps=0.5, label="walk")),
               pushes=((1.6, (60.0, 0.0, 0.0)),))


def test_a_rows_result_does_not_depend_on_the_rows_run_before_it_in_the_process():
    """Issue 26 item 4: a row's outcome is a function of its case alone. Run in two orders in one
    process, each row gives the same bytes in its whole per-tick log (a controller's state carried
    from one loop to the next, a solver warm-started from another tracker's solution or a memo whose
    values depend on history would change the bits: the WBC walks near its limits, where such
    rounding-level differences grow)."""
    first = [B.run_case("wbc", case, 0.0) for case in (_TURN, _PUSH)]
    second = [B.run_case("wbc", case, 0.0) for case in (_PUSH, _TURN)][::-1]
    for a, b in zip(first, second):
        assert a.sim_s == pytest.approx(3.0) and not a.fell, a
        assert a.log_sha256 == b.log_sha256, f"{a.case}: the row's log differs when run after another row"
    assert first[0].log_sha256 != first[1].log_sha256  # the digest tells different runs apart
    assert first[1].pushes_survived == 1


def test_the_rows_give_the_same_bytes_in_two_processes(tmp_path):
    """The same two rows in two fresh processes, in opposite orders, with the heap shifted by different
    amounts and different string hash seeds (set and dict orders of str keys): the same digests."""
    code = ("import json, sys; pad = bytearray(1024 + 16 * int(sys.argv[1])); "
            "from g1_control.tools import bench_locomotion as B; "
            "from tests.tools.test_bench_locomotion import _PUSH, _TURN; "
            "cases = [_TURN, _PUSH] if sys.argv[1] == '0' else [_PUSH, _TURN]; "
            "print(json.dumps({c.name: B.run_case('wbc', c, 0.0).log_sha256 for c in cases}))")
    digests = []
    for shift in (0, 1):
        env = {**os.environ, "PYTHONHASHSEED": str(shift),
               "PYTHONPATH": str(REPO) + os.pathsep + os.environ.get("PYTHONPATH", "")}
        proc = subprocess.run([sys.executable, "-c", code, str(shift)], cwd=REPO, env=env, capture_output=True,
                              text=True, timeout=300, check=False)
        assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-3000:]
        digests.append(json.loads(proc.stdout.strip().splitlines()[-1]))
    assert set(digests[0]) == {"turn", "push"}
    assert digests[0] == digests[1]
    # and the same as in this process
    assert digests[0]["turn"] == B.run_case("wbc", _TURN, 0.0).log_sha256


def test_log_digest_covers_every_tick_of_the_ground_truth():
    log = {name: np.zeros((5, 3)) for name in B.LOG_DIGEST_FIELDS}
    base = B.log_digest(log)
    log["base_pos_m"][4, 2] = np.nextafter(0.0, 1.0)  # the last tick, the smallest change there is
    assert B.log_digest(log) != base
    log["base_pos_m"][4, 2] = 0.0
    assert B.log_digest(log) == base
    assert B.log_digest({**log, "q_rad": np.zeros((4, 3))}) != base  # one tick fewer
