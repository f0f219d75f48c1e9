"""g1 replay / g1 view: playbacks from run folders and clips, their overlay, the gait-cycle mean."""

import json

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
    assert rc == 0, capsys.readouterr().err  # no EGL/OSMesa: scripts/setup.sh --test installs them (root)
    frame = imageio.imread(tmp_path / "run" / "replay-1s.png")
    assert frame.shape[:2] == (240, 320)
    assert main(["view", str(clip), "--frame", "0.1", "-o", str(tmp_path / "clip.png"), "--size", "320", "240"]) == 0
    view = imageio.imread(tmp_path / "clip.png")
    # the overlay's dark box with white text sits in the top-left corner
    corner = view[4:40, 4:150, :3].astype(int)
    assert (corner.sum(axis=2) > 600).sum() > 50 and (corner.sum(axis=2) < 120).sum() > 500


BOX_SCENE = {"tables": [{"name": "table_a", "center_xy_m": [1.0, -0.8], "size_xy_m": [0.5, 0.8], "height_m": 0.7}],
             "boxes": [{"name": "box", "stands_on": "table_a", "xy_m": [1.0, -0.8], "size_m": [0.3, 0.3, 0.3],
                        "mass_kg": 2.0}]}
BOX_NEAR = [0.7, 0.0, 0.9, 1.0, 0.0, 0.0, 0.0]
"""Where truth.npz says the box is for t < 1 s: in the air in front of the robot (nowhere the
launch file put it, so a replay that draws the box at its start pose is caught)."""
BOX_FAR = [40.0, 40.0, 0.15, 1.0, 0.0, 0.0, 0.0]
"""...and from 1 s on: far out of sight."""


def _fake_box_run(folder, n=100):
    """A standing robot's run folder with a scene (launch.yaml) and the box's recorded poses (truth.npz)."""
    import yaml

    log = _fake_run(folder, n)
    log["base_pos_m"][:] = [0.0, 0.0, 0.76]
    np.savez(folder / "log.npz", **log)
    (folder / "launch.yaml").write_text(yaml.safe_dump({"name": "fake", "scene": BOX_SCENE}))
    t = np.arange(n) * 0.02
    poses = np.where((t < 1.0)[:, None], BOX_NEAR, BOX_FAR)
    np.savez(folder / "truth.npz", t_s=t, box_box=poses, hands_w_m=np.zeros((n, 2, 3)))


def test_run_replay_builds_the_scene_and_moves_the_box_from_truth(tmp_path):
    import mujoco

    _fake_box_run(tmp_path / "run")
    pb = replay.from_run(tmp_path / "run")
    assert pb.scene is not None, "the run's scene (launch.yaml) is left out of the replay"
    model = replay.replay_model(pb.scene)
    data = mujoco.MjData(model)
    assert model.geom("table_a_top").id >= 0 and model.body("box").id >= 0
    for i, expected in ((10, BOX_NEAR), (80, BOX_FAR)):
        replay.pose(pb, model, data, i)
        mujoco.mj_kinematics(model, data)
        np.testing.assert_allclose(data.xpos[model.body("box").id], expected[:3], atol=1e-9)
        np.testing.assert_allclose(data.qpos[:3], [0.0, 0.0, 0.76])  # the robot's own pose is untouched


def test_run_without_a_scene_replays_the_robot_alone(tmp_path):
    _fake_run(tmp_path / "run")
    assert replay.from_run(tmp_path / "run").scene is None


def test_clip_scene_and_object_are_drawn(tmp_path):
    import mujoco

    from g1_control.motion.objects import ObjectShape, ObjectTrack

    n = 20
    step = ObjectShape.box("step", (0.3, 0.5, 0.1)).transformed(np.eye(3), np.array([1.0, 0.0, 0.1]))
    track = ObjectTrack(ObjectShape.box("crate", (0.2, 0.2, 0.2)),
                        np.column_stack([np.linspace(0.5, 1.5, n), np.zeros(n), np.full(n, 0.8)]),
                        np.tile([1.0, 0, 0, 0], (n, 1)))
    base = _clip(n)
    clip = MotionClip.from_joint_trajectory(50.0, base.root_pos_w_m, base.root_quat_wxyz, base.joint_pos_rad,
                                            source="box_clip", object=track, scene=(step,))
    path = tmp_path / "clip.npz"
    save_clip(clip, path)
    pb = replay.from_clip(path)
    assert pb.scene is not None and len(pb.scene.shapes_w_m) == 1 and len(pb.scene.movers_m) == 1
    model = replay.replay_model(pb.scene)
    data = mujoco.MjData(model)
    replay.pose(pb, model, data, 15)
    mujoco.mj_forward(model, data)
    mover = model.body("object_crate").id
    np.testing.assert_allclose(data.xpos[mover], track.pos_w_m[15], atol=1e-9)
    shape = model.geom("shape_0_step").id
    np.testing.assert_allclose(data.geom_xpos[shape], [1.0, 0.0, 0.1], atol=1e-6)  # the hull's centre


def _projected_pixel(model, point_w, qpos, size):
    """Where `point_w` lands in the replay video's frame (render.py's tracking camera), in pixels
    (column, row): the camera MuJoCo's scene update computes, no GL needed."""
    import mujoco

    from g1_control.sim.render import tracking_camera

    data = mujoco.MjData(model)
    data.qpos[:len(qpos)] = qpos
    mujoco.mj_forward(model, data)
    scene = mujoco.MjvScene(model, maxgeom=2000)
    mujoco.mjv_updateScene(model, data, mujoco.MjvOption(), None, tracking_camera(model),
                           mujoco.mjtCatBit.mjCAT_ALL, scene)
    cam = scene.camera[0]
    forward, up = np.asarray(cam.forward), np.asarray(cam.up)
    right = np.cross(forward, up)
    d = np.asarray(point_w) - np.asarray(cam.pos)
    depth = d @ forward
    x = (d @ right) / depth * cam.frustum_near  # on the near plane
    y = (d @ up) / depth * cam.frustum_near
    w, h = size
    half_w = cam.frustum_top * w / h  # MuJoCo's frustum is symmetric, its width set by the aspect
    col = (x / half_w + 1.0) / 2.0 * w
    row = (1.0 - (y / cam.frustum_top + 1.0) / 2.0) * h
    return round(float(col)), round(float(row))


def _box_coloured(rgb) -> bool:
    r, g, b = (int(c) for c in rgb[:3])
    return g > 50 and g > 1.8 * r and g > 1.8 * b  # the box's green (sim/scene.py BOX_RGBA), lit or shaded


@pytest.mark.slow
def test_replay_frame_draws_the_box_where_truth_says(tmp_path, capsys):
    _fake_box_run(tmp_path / "run")
    size = (320, 240)
    rc = main(["replay", str(tmp_path / "run"), "--frame", "0.5", "--size", *map(str, size)])
    assert rc == 0, capsys.readouterr().err  # no EGL/OSMesa: scripts/setup.sh --test installs them (root)
    assert main(["replay", str(tmp_path / "run"), "--frame", "1.5", "--size", *map(str, size)]) == 0
    near = imageio.imread(tmp_path / "run" / "replay-0.5s.png")
    far = imageio.imread(tmp_path / "run" / "replay-1.5s.png")
    pb = replay.from_run(tmp_path / "run")
    col, row = _projected_pixel(replay.replay_model(pb.scene), BOX_NEAR[:3], pb.qpos(25), size)
    assert 0 <= col < size[0] and 0 <= row < size[1]
    patch = near[row - 2:row + 3, col - 2:col + 3]
    assert all(_box_coloured(p) for p in patch.reshape(-1, patch.shape[-1])), \
        f"no box at its recorded place (pixel {col},{row}: {near[row, col]})"
    assert not _box_coloured(far[row, col]), "the box stayed where it was after truth.npz moved it away"
    table = sum(_box_coloured(p) for p in far.reshape(-1, far.shape[-1]))
    assert table < 5  # once it has gone, nothing box-coloured remains


def test_a_bottle_is_drawn_and_moved_from_truth_in_a_run_replay():
    """A scene with only a bottle on a table: the replay draws the bottle (sim/scene.add_bottles) where
    the ground-truth recorder put it (truth key bottle_<name>), not where the scene first stood it."""
    import mujoco

    scene = {"tables": [{"name": "t", "center_xy_m": [0.6, 0.0], "size_xy_m": [0.5, 0.8], "height_m": 0.7}],
             "bottles": [{"name": "b", "stands_on": "t", "xy_m": [0.45, 0.0], "height_m": 0.2}]}
    t = np.array([0.0, 1.0])
    carried = np.array([[0.45, 0.0, 0.8, 1, 0, 0, 0], [0.2, 0.3, 1.0, 1, 0, 0, 0]])
    rs = replay.scene_with_truth(scene, {"t_s": t, "bottle_b": carried})
    assert rs is not None and set(rs.object_poses) == {"b"}
    model = replay.replay_model(rs)
    data = mujoco.MjData(model)
    rs.pose(model, data, 1.5)
    mujoco.mj_kinematics(model, data)
    np.testing.assert_allclose(data.xpos[model.body("b").id], carried[1, :3])
    only_bottles = {"bottles": [{"name": "b", "xy_m": [1.0, 0.0], "height_m": 0.2}]}
    assert replay.scene_with_truth(only_bottles, {}) is not None, "a bottle on the floor is a scene too"
