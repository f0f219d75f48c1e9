"""`g1 check` on clip files from this project and from other tools."""

import json
import pickle

import numpy as np

from g1_control.cli.main import main
from g1_control.motion.clip import MotionClip
from g1_control.motion.formats.clip_npz import write_clip_npz
from g1_control.motion.objects import ObjectShape
from tests.retarget.standing_clips import standing_clip


def _standing(t: int = 20) -> MotionClip:
    return standing_clip(t)


def test_clean_clip_passes_and_a_sliding_gmr_clip_fails(tmp_path, capsys):
    clean = tmp_path / "stand.npz"
    write_clip_npz(_standing(), clean)
    assert main(["check", str(clean), "--json", str(tmp_path / "r.json")]) == 0
    out = capsys.readouterr().out
    assert "1 of 1 clip(s) meet the acceptance figures" in out
    report = json.loads((tmp_path / "r.json").read_text())
    assert report[0]["passes"] and report[0]["sliding_frames"] == 0

    clip = _standing()
    root = clip.root_pos_w_m.copy()
    root[10:, 0] += 0.03  # both feet dragged 3 cm on the floor in one frame
    gmr = tmp_path / "drag.pkl"
    with gmr.open("wb") as f:
        pickle.dump({"fps": 30.0, "root_pos": root, "root_rot": np.tile([0.0, 0, 0, 1], (20, 1)),
                     "dof_pos": clip.joint_pos_rad}, f)
    assert main(["check", str(gmr), str(clean)]) == 1
    out = capsys.readouterr().out
    assert "outside them: drag.pkl" in out


def test_scene_option_and_mujoco_cross_check(tmp_path, capsys):
    clip = _standing()
    path = tmp_path / "stand.npz"
    write_clip_npz(clip, path)
    # a deep block the feet stand in, as an OBJ file: its top 5 cm above the soles (the depth is the
    # shortest way out, so the block is deep enough that the way out is up)
    plate = ObjectShape.box("plate", (0.5, 0.5, 0.25)).transformed(np.eye(3), np.array([0.0, 0.0, -0.2]))
    obj = tmp_path / "plate.obj"
    obj.write_text("".join(f"v {x} {y} {z}\n" for x, y, z in plate.vertices()))
    assert main(["check", str(path), "--scene", str(obj), "--mujoco", "--plot", str(tmp_path / "plots"),
                 "--json", str(tmp_path / "r.json")]) == 1
    out = capsys.readouterr().out
    assert "ankle_roll_link" in out and "MuJoCo finds 0 self-collision and 20 penetration frames" in out
    report = json.loads((tmp_path / "r.json").read_text())[0]
    assert abs(report["max_penetration_m"] - 0.05) < 1e-6 and report["mujoco"]["frames_agreeing_penetration"] == 20
    assert (tmp_path / "plots" / "stand.png").stat().st_size > 10_000


def test_human_motion_and_missing_files_are_reported(tmp_path, capsys):
    human = tmp_path / "person.npz"
    np.savez(human, fps=30)
    assert main(["check", str(tmp_path / "nope.npz"), str(human)]) == 1
    err = capsys.readouterr().err
    assert "nope.npz: no such file" in err and "person.npz" in err
