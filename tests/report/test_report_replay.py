"""g1 replay / g1 view: playbacks from run folders and clips, their overlay, the gait-cycle mean."""

import json
import os

import imageio.v2 as imageio
import numpy as np
import pytest

from g1_control.cli.main import main
from g1_control.motion.clip import MotionClip
from g1_control.motion.formats.dispatch import save_clip
from g1_control.report import replay
from g1_control.report.overlay import run_overlay_rows, safety_state_at
from g1_control.report.plots import window_mean
from g1_control.robot import g1


def test_window_mean_removes_a_gait_oscillation():
    t = np.arange(0, 10, 0.02)
    v = 0.5 + 0.3 * np.sin(2 * np.pi * t / 1.0)  # a 1 s gait swing around 0.5 m/s
    mean = window_mean(t, v, 1.0)
    inner = (t > 1) & (t < 9)
    assert np.abs(mean[inner] - 0.5).max() < 0.01
    assert np.abs(v[inner] - 0.5).max() > 0.29
    # NaN samples are skipped, an all-NaN window gives NaN, shapes are kept
    x = np.column_stack([v, np.full_like(v, np.nan)])
    x[100:110, 0] = np.nan
    m = window_mean(t, x, 1.0)
    assert m.shape == x.shape and np.isfinite(m[:, 0]).all() and np.isnan(m[:, 1]).all()


def test_safety_state_from_events():
    events = [{"t_s": 2.0, "kind": "input_stale", "detail": "no input for 0.3 s", "trips": False},
              {"t_s": 4.0, "kind": "invalid_command", "detail": "says damping in its text"},
              {"t_s": 5.0, "kind": "tilt", "detail": "tilt 1.1 rad > 1.0", "trips": True}]
    assert safety_state_at(1.0, events) == "ok"
    assert safety_state_at(2.5, events) == "warning: input_stale"
    assert safety_state_at(4.5, events) == "warning: invalid_command", "a word in a detail is no trip"
    assert safety_state_at(5.0, events) == "DAMPING (tilt)"
    assert safety_state_at(30.0, events) == "DAMPING (tilt)"


def _fake_run(folder, n=100):
    t = np.arange(n) * 0.02
    q = np.tile(np.asarray(g1.DEFAULT_Q_RAD), (n, 1))
    log = {"t_s": t, "command": np.tile([0.5, 0.0, 0.0], (n, 1)), "policy_command": np.zeros((n, 3)),
           "velocity_est": np.tile([0.45, 0.0, 0.0], (n, 1)), "velocity_true": np.tile([0.48, 0.0, 0.0], (n, 1)),
           "base_pos_m": np.column_stack([0.48 * t, np.zeros(n), np.full(n, 0.76)]),
           "base_quat_wxyz": np.tile([1.0, 0, 0, 0], (n, 1)), "yaw_rad": np.zeros(n), "tilt_rad": np.zeros(n),
           "q_rad": q, "q_target_rad": q, "tau_nm": np.zeros((n, 29))}
    folder.mkdir()
    np.savez(folder / "log.npz", **log)
    summary = {"name": "fake", "events": [{"t_s": 1.5, "kind": "tilt", "detail": "tilt", "trips": True}],
               "segments": [{"label": "forward", "start_s": 0.0, "end_s": 2.0}]}
    (folder / "summary.json").write_text(json.dumps(summary))
    return log


def test_run_playback_overlay(tmp_path):
    _fake_run(tmp_path / "run")
    pb = replay.from_run(tmp_path / "run")
    assert pb.title == "run fake" and len(pb.overlay) == 100
    assert "forward" in pb.overlay[10] and "command   vx +0.50" in pb.overlay[10]
    assert "achieved  vx +0.48" in pb.overlay[10] and "safety    ok" in pb.overlay[10]
    assert "DAMPING (tilt)" in pb.overlay[90]
    assert pb.qpos(0).shape == (36,)
    assert replay.is_run_log(tmp_path / "run") and replay.is_run_log(tmp_path / "run" / "log.npz")


def test_overlay_uses_the_estimate_on_a_robot():
    n = 50
    log = {"t_s": np.arange(n) * 0.02, "command": np.zeros((n, 3)), "velocity_true": np.full((n, 3), np.nan),
           "velocity_est": np.tile([0.2, 0.0, 0.0], (n, 1))}
    rows = run_overlay_rows(log, [])
    assert "vx +0.20" in rows[25] and "(estimate, 1 s mean)" in rows[25]


def _clip(n=20):
    t = np.arange(n) / 50.0
    root = np.column_stack([0.3 * t, np.zeros(n), np.full(n, 0.78)])
    return MotionClip.from_joint_trajectory(50.0, root, np.tile([1.0, 0, 0, 0], (n, 1)),
                                            np.tile(np.asarray(g1.DEFAULT_Q_RAD), (n, 1)), source="test_clip")


@pytest.mark.parametrize("ext", ["npz", "csv"])
def test_clip_playback_any_format(tmp_path, ext):
    path = tmp_path / f"clip.{ext}"
    save_clip(_clip(), path)
    pb = replay.from_clip(path)
    assert len(pb.t_s) == 20 and pb.base_pos_m.shape == (20, 3)
    assert "frame 1/20" in pb.overlay[0] and "feet in contact" in pb.overlay[0]
    np.testing.assert_allclose(pb.q_rad[5], g1.DEFAULT_Q_RAD, atol=1e-6)


def test_view_refuses_human_mocap_with_advice(tmp_path):
    from g1_control.errors import G1ControlError

    human = tmp_path / "walk.bvh"
    human.write_text("HIERARCHY\n")
    with pytest.raises(G1ControlError):
        replay.from_clip(human)


@pytest.mark.slow
def test_replay_and_view_write_frames_with_overlay(tmp_path, capsys):
    _fake_run(tmp_path / "run")
    clip = tmp_path / "clip.npz"
    save_clip(_clip(), clip)
    rc = main(["replay", str(tmp_path / "run"), "--frame", "1.0", "--size", "320", "240"])
    if rc != 0 and "no headless rendering" in capsys.readouterr().err and not os.environ.get("CI"):
        pytest.skip("no EGL/OSMesa here (scripts/setup.sh installs them with root; CI fails instead)")
    assert rc == 0
    frame = imageio.imread(tmp_path / "run" / "replay-1s.png")
    assert frame.shape[:2] == (240, 320)
    assert main(["view", str(clip), "--frame", "0.1", "-o", str(tmp_path / "clip.png"), "--size", "320", "240"]) == 0
    view = imageio.imread(tmp_path / "clip.png")
    # the overlay's dark box with white text sits in the top-left corner
    corner = view[4:40, 4:150, :3].astype(int)
    assert (corner.sum(axis=2) > 600).sum() > 50 and (corner.sum(axis=2) < 120).sum() > 500
