"""launch/sim_tour.yaml, the README's first command: it validates and holds the whole chain (the
generator's styles at walking speed, a reach, a box picked and placed, a step up and down, a
push); pushes in launch files and how the summary judges them (launch/runner.py)."""

from pathlib import Path

import numpy as np
import pytest

from g1_control.cli.main import main
from g1_control.errors import LaunchFileError
from g1_control.launch.runner import PUSH_WINDOW_S, push_outcomes
from g1_control.launch.schema import PushConfig, load_launch, parse_launch
from g1_control.report.results import push_line

REPO = Path(__file__).resolve().parents[2]


def test_the_tour_validates_by_name_and_by_path(capsys):
    assert main(["launch", "sim_tour", "--check"]) == 0
    assert main(["launch", str(REPO / "launch" / "sim_tour.yaml"), "--check"]) == 0
    assert capsys.readouterr().out.count("OK (sim_tour: mujoco lockstep") == 2


def test_the_tour_goes_through_the_whole_chain():
    launch = load_launch(REPO / "launch" / "sim_tour.yaml")
    assert launch.generator.type == "backbone" and launch.tracker.type == "layer"
    timeline = launch.input.timeline
    walking_styles = {s.style for s in timeline if np.hypot(s.vx_mps, s.vy_mps) >= 0.2}
    assert len(walking_styles - {"default"}) >= 2
    kinds = [g.kind for s in timeline for g in s.goals]
    assert {"reach", "pick", "place", "step_up", "step_down"} <= set(kinds)
    assert launch.pushes and all(p.at_s < launch.total_duration_s - PUSH_WINDOW_S for p in launch.pushes)
    assert launch.output.video in (True, "auto") and launch.output.plot
    assert launch.total_duration_s <= 100.0


def _with_push(push: dict, **more) -> dict:
    return {"name": "t", "input": {"type": "scripted", "timeline": [{"duration_s": 5.0}]}, "pushes": [push], **more}


def test_pushes_are_validated():
    launch = parse_launch(_with_push({"at_s": 1.0, "force_h_n": [0.0, 80.0, 0.0]}))
    assert launch.pushes == [PushConfig(1.0, (0.0, 80.0, 0.0))]
    with pytest.raises(LaunchFileError, match=r"pushes\[0\]: at_s must be >= 0 and duration_s in \(0, 2\] s"):
        parse_launch(_with_push({"at_s": 1.0, "force_h_n": [0.0, 80.0, 0.0], "duration_s": 0.0}))
    with pytest.raises(LaunchFileError, match=r"pushes\[0\]\.force_h_n"):
        parse_launch(_with_push({"at_s": 1.0, "force_h_n": [0.0, 80.0]}))
    with pytest.raises(LaunchFileError, match="only a simulated run"):
        parse_launch(_with_push({"at_s": 1.0, "force_h_n": [0.0, 80.0, 0.0]},
                                backend={"type": "unitree_dds", "interface": "lo"}))


def _log(tilt: np.ndarray) -> dict[str, np.ndarray]:
    t = np.arange(len(tilt)) * 0.01
    return {"t_s": t, "tilt_rad": tilt, "base_pos_m": np.column_stack([0.3 * t, np.zeros_like(t), np.full_like(t, 0.78)])}


def test_a_push_is_judged_from_the_logged_tilt_and_a_fall():
    tilt = np.full(1000, 0.03)
    tilt[210:260] = np.linspace(0.03, 0.25, 50)  # pushed at 2.0 s: leans to 0.25 rad, upright from 2.9 s
    tilt[260:290] = np.linspace(0.25, 0.05, 30)
    push = PushConfig(2.0, (0.0, 100.0, 0.0), 0.2, "from the right")
    [ok] = push_outcomes([push], _log(tilt), None)
    assert ok["recovered"] and not ok["fell"]
    assert ok["peak_tilt_rad"] == pytest.approx(0.25) and ok["upright_after_s"] == pytest.approx(0.8, abs=0.02)
    assert ok["moved_m"] == pytest.approx(0.3 * PUSH_WINDOW_S, abs=0.01)
    assert "recovered; peak tilt 0.25 rad" in push_line(ok) and "100 N for 0.20 s" in push_line(ok)
    [fell] = push_outcomes([push], _log(tilt), {"t_s": 3.1, "kind": "tilt", "detail": "x"})
    assert fell["fell"] and not fell["recovered"] and push_line(fell).endswith("FELL")
    still = tilt.copy()
    still[260:] = 0.3  # never upright again
    [leaning] = push_outcomes([push], _log(still), None)
    assert not leaning["recovered"] and "not upright again" in push_line(leaning)
    [later] = push_outcomes([push], _log(tilt), {"t_s": 8.0, "kind": "tilt", "detail": "x"})
    assert later["recovered"]  # a fall long after the push is not the push's
