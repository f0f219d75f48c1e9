"""`g1 bench stairs` courses and draws, without physics: the scene holds the treads where the
course says (turned and offset as drawn), draws repeat per seed and stay within their bounds."""

import math

import numpy as np
import pytest

from g1_control.tools.bench_stairs import (
    COP_JUMP_M,
    MAX_ANGLE_DEG,
    MAX_OFFSET_M,
    NEAR_EDGE_M,
    CopJumps,
    course_scene,
    draw,
)


def test_stairs_go_up_three_treads_to_the_landing_and_down_along_the_turned_axis():
    angle, offset = math.radians(20.0), 0.2
    scene, top, far = course_scene("stairs", angle, offset)
    axis = np.array([math.cos(angle), math.sin(angle)])
    origin = np.array([NEAR_EDGE_M, offset])
    heights = [scene.ground_height(origin + s * axis) for s in (-0.05, 0.1, 0.6, 1.0, 1.5, 2.3, 2.7, 3.1)]
    assert heights == pytest.approx([0.0, 0.15, 0.30, 0.45, 0.45, 0.30, 0.15, 0.0])
    assert top == pytest.approx(0.45) and far == pytest.approx(3.0)
    scene.validate("scene")  # nothing within reach of the robot's start


def test_platform_is_020_m():
    scene, top, far = course_scene("platform", 0.0, 0.0)
    assert far == pytest.approx(1.2)
    assert top == pytest.approx(0.20) and scene.ground_height(np.array([NEAR_EDGE_M + 0.6, 0.0])) == pytest.approx(0.20)


def test_draws_repeat_per_seed_within_bounds():
    assert draw(7) == draw(7) and draw(7) != draw(8)
    for seed in range(50):
        a, o = draw(seed)
        assert abs(a) <= MAX_ANGLE_DEG and abs(o) <= MAX_OFFSET_M


def test_unknown_course_is_named():
    with pytest.raises(ValueError, match="unknown course 'ramp'; known: stairs, platform, step"):
        course_scene("ramp", 0.0, 0.0)


def test_cop_jumps_count_ticks_that_jump_within_a_contact_phase_only():
    jumps = CopJumps()
    for k in range(50):  # a CoP walking 4 mm a tick across the sole: smooth
        jumps.update(("walk", 0, 1), np.array([0.004 * k, 0.0]))
    assert (jumps.jumps, jumps.ticks) == (0, 49)
    jumps.update(("walk", 1, -1), np.array([0.0, -0.2]))  # the stance changes: moves far, not a jump
    assert (jumps.jumps, jumps.ticks) == (0, 49)
    for k in range(10):  # then between the sole's two ends every tick (stop 48's chatter)
        jumps.update(("walk", 1, -1), np.array([(-1) ** k * 0.05, -0.2]))
    assert (jumps.jumps, jumps.ticks) == (10, 59)
    edge = CopJumps()
    edge.update(0, np.zeros(2))
    edge.update(0, np.array([COP_JUMP_M * 0.99, 0.0]))
    edge.update(0, np.array([COP_JUMP_M * 0.99 - COP_JUMP_M * 1.01, 0.0]))
    assert (edge.jumps, edge.ticks) == (1, 2)


def test_a_trial_traces_the_feet_the_gait_and_the_balance_every_50th_of_a_second(tmp_path):
    import csv

    from g1_control.tools.bench_stairs import TRACE_COLUMNS, _write_trace, run_course

    rows: list = []
    trial = run_course("step", 0, duration_s=2.0, trace=rows)
    assert not trial.fell and len(rows) == 100 and all(len(r) == len(TRACE_COLUMNS) for r in rows)
    # standing, then starting to walk on the floor: every tick counted (250 Hz, less the phase changes)
    # and the CoP asked never jumps
    assert trial.cop_jumps == 0 and 480 <= trial.cop_ticks < 500
    # the controller's act() timed every tick (2 s at 250 Hz), its state kept every 10th for the baseline
    assert len(trial.act_cpu_us) == 500 and all(c > 0 for c in trial.act_cpu_us)
    assert len(trial.states) == 50 and trial.states[0][0].shape == (36,) and trial.states[0][1].shape == (35,)
    col = {name: i for i, name in enumerate(TRACE_COLUMNS)}
    times = np.array([r[col["t_s"]] for r in rows])
    np.testing.assert_allclose(np.diff(times), 0.02, atol=1e-6)
    assert rows[0][col["mode"]] == "stand" and rows[-1][col["mode"]] in ("start", "walk")
    start = rows[0]
    # standing on the floor 1 m before the course's near edge (0.3 m beside its axis at most)
    assert abs(start[col["left_z_m"]]) < 0.01 and abs(start[col["right_z_m"]]) < 0.01
    assert -1.3 < start[col["left_along_m"]] < -0.6 and 0.6 < start[col["pelvis_above_ground_m"]] < 0.85
    assert all(0.0 <= r[col["speed_fraction"]] < 1.0 for r in rows)
    _write_trace(tmp_path / "t" / "step_0.csv", rows)
    with (tmp_path / "t" / "step_0.csv").open() as f:
        read = list(csv.reader(f))
    assert tuple(read[0]) == TRACE_COLUMNS and len(read) == 101 and read[1][col["mode"]] == "stand"


def test_the_bench_reports_the_controller_s_cpu_per_course_beside_rnea_crba(tmp_path, capsys):
    """`g1 bench stairs`: per course, act()'s thread CPU p50/p99 (and p50 over RNEA + CRBA on the visited
    states, measured in the same run), and each trial's p50/p99 in --json."""
    import json
    from types import SimpleNamespace

    from g1_control.tools.bench_stairs import main

    out = tmp_path / "s.json"
    code = main(SimpleNamespace(only="step", seed=1, trials=1, json=str(out), trace=None))
    printed = capsys.readouterr().out
    trial = json.loads(out.read_text())[0]
    assert code == (1 if trial["fell"] else 0)
    line = next(ln for ln in printed.splitlines() if ln.startswith("step: "))
    assert "act() CPU p50" in line and "x RNEA+CRBA), p99" in line and "% of the 4 ms tick" in line
    assert "baseline, same run: pinocchio RNEA + CRBA" in printed
    assert 0 < trial["act_cpu_p50_us"] <= trial["act_cpu_p99_us"] and "states" not in trial and "act_cpu_us" not in trial
