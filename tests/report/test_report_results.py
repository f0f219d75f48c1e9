"""A run's figures from its log (g1_control/report/results.py), on synthetic logs with known answers."""

from __future__ import annotations

import json

import numpy as np
import pytest

from g1_control.report.results import (
    STEADY_STATE_SKIP_S,
    UPPER_BODY,
    RunResult,
    SegmentResult,
    fall_text,
    format_summary,
    program_summary,
    segment_results,
    segments_from_log,
    summary_dict,
    upper_body_rms,
    upper_body_rms_by_style,
)
from g1_control.teleop.scripted import Segment

DT = 0.02


def _log(commands: list[tuple[float, tuple[float, float, float]]], achieved_gain: float = 0.9) -> dict[str, np.ndarray]:
    """Ticks at 50 Hz through (duration, command) pieces; the robot makes `achieved_gain` of each
    command after the first second of its piece, 0 before; the upper body 0.05 rad off its reference."""
    t, cmd, vel = [], [], []
    start = 0.0
    for duration, c in commands:
        n = round(duration / DT)
        for k in range(n):
            t.append(start + k * DT)
            cmd.append(c)
            vel.append(np.asarray(c) * (achieved_gain if k * DT >= 1.0 else 0.0))
        start += duration
    n = len(t)
    q_ref = np.zeros((n, 29))
    q = q_ref.copy()
    q[:, UPPER_BODY] = 0.05
    return {"t_s": np.asarray(t), "command": np.asarray(cmd, dtype=float), "velocity_true": np.asarray(vel),
            "velocity_est": np.full((n, 3), np.nan), "q_rad": q, "q_ref_rad": q_ref,
            "style_id": np.zeros(n, dtype=int), "style_names": np.asarray(["default"])}


def test_segment_results_average_the_steady_state_of_each_segment():
    log = _log([(4.0, (0.0, 0.0, 0.0)), (6.0, (0.5, 0.0, 0.2))])
    segments = [Segment(4.0, label="stand"), Segment(6.0, vx_mps=0.5, wz_radps=0.2, label="walk")]
    stand, walk = segment_results(log, segments)
    assert (stand.label, stand.start_s, stand.end_s) == ("stand", 0.0, 4.0)
    assert (walk.start_s, walk.end_s, walk.commanded) == (4.0, 10.0, (0.5, 0.0, 0.2))
    assert STEADY_STATE_SKIP_S >= 1.0  # the first second (not yet moving) is skipped
    assert walk.achieved == pytest.approx((0.45, 0.0, 0.18))
    assert walk.error_pct()[0] == pytest.approx(-10.0)
    assert walk.error_pct()[1] is None  # no command on that axis: no relative error
    assert walk.error_pct()[2] == pytest.approx(-10.0)
    assert walk.upper_body_rms_rad == pytest.approx(0.05)


def test_without_a_timeline_segments_come_from_the_log():
    log = _log([(3.0, (0.0, 0.0, 0.0)), (0.5, (0.2, 0.0, 0.0)), (5.0, (0.4, 0.0, 0.0))])
    found = segments_from_log(log)
    assert [(round(s, 2), seg.duration_s, seg.vx_mps) for s, seg in found] == [(0.0, 3.0, 0.0), (3.5, 5.0, 0.4)]
    assert [r.label for r in segment_results(log, [])] == ["held", "held"]


def test_upper_body_rms_needs_a_reference():
    log = _log([(2.0, (0.0, 0.0, 0.0))])
    rows = np.ones(len(log["t_s"]), dtype=bool)
    assert upper_body_rms(log, rows) == pytest.approx(0.05)
    log["q_ref_rad"][:] = np.nan
    assert upper_body_rms(log, rows) is None
    log = _log([(4.0, (0.0, 0.0, 0.0))])
    by_style = upper_body_rms_by_style(log, settle_s=1.0)
    assert list(by_style) == ["default"]
    assert by_style["default"]["rms_rad"] == pytest.approx(0.05)
    assert by_style["default"]["seconds"] == pytest.approx(3.0, abs=DT)


def test_summary_and_report():
    result = RunResult(name="walk", fell=True, duration_s=10.0, wall_s=2.5,
                       segments=[SegmentResult("walk", 4.0, 10.0, (0.5, 0.0, 0.0), (0.45, 0.0, 0.0), 0.05)],
                       timings={"tracker": {"calls": 500, "p50_us": 50.0, "p99_us": 90.0, "max_us": 120.0}},
                       deadline_misses=0, overruns=1, events=[{"t_s": 9.5, "kind": "fall", "detail": "tilt; damping"}],
                       estimator_rms_mps=None, fall={"t_s": 9.5, "kind": "tilt", "detail": "tilt 1.1 rad"})
    assert result.real_time_factor == 4.0
    d = summary_dict(result)
    json.dumps(d)  # summary.json holds it
    assert d["real_time_factor"] == 4.0 and d["run_dir"] is None
    assert d["segments"][0]["error_pct"][0] == pytest.approx(-10.0)
    assert fall_text(None) == "no fall"
    assert fall_text(result.fall) == "FELL at 9.50 s: tilt 1.1 rad"
    text = format_summary(result)
    assert text.startswith("run 'walk': FELL at 9.50 s: tilt 1.1 rad; 10.0 s simulated in 2.5 s wall (real-time factor 4.0x)")
    assert "-10.0" in text and "0.050" in text and "ticks over budget: 1" in text
    assert "event at 9.50 s: fall: tilt; damping" in text


def test_program_summary_counts_ground_truth_verdicts():
    steps = [{"label": "1", "description": "walk 1 m", "status": "completed", "started_s": 0.0, "ended_s": 3.0,
              "verdict": {"ok": True, "text": "walked 0.97 m"}},
             {"label": "2", "description": "turn left", "status": "completed", "started_s": 3.0, "ended_s": 5.5,
              "verdict": {"ok": False, "text": "turned 70 deg of 90"}},
             {"label": "3", "description": "wave", "status": "completed", "started_s": 5.5, "ended_s": 7.5}]
    text = program_summary({"steps": steps, "finished": False, "pose": "estimator"})
    assert text.splitlines() == [
        "program (steered by estimator): 3 steps ran, STOPPED before the end; 1/2 met by ground truth",
        "  1. walk 1 m: completed after 3.0 s | walked 0.97 m OK",
        "  2. turn left: completed after 2.5 s | turned 70 deg of 90 MISSED",
        "  3. wave: completed after 2.0 s"]
