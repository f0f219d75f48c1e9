"""`g1 train generator` on a library whose held-out split is empty says so (no traceback)."""

from __future__ import annotations

import json

import numpy as np

from g1_control.cli.main import main
from g1_control.motion.clip import MotionClip
from g1_control.motion.formats.clip_npz import write_clip_npz
from g1_control.robot import g1


def test_empty_held_out_split_is_refused_by_name(tmp_path, capsys):
    t = 90
    joints = np.tile(g1.DEFAULT_Q_RAD, (t, 1))
    root = np.column_stack([np.linspace(0, 0.4, t), np.zeros(t), np.full(t, 0.78)])
    quat = np.tile([1.0, 0.0, 0.0, 0.0], (t, 1))
    clip = MotionClip.from_joint_trajectory(30.0, root, quat, joints, source="synthetic")
    (tmp_path / "clips").mkdir()
    write_clip_npz(clip, tmp_path / "clips" / "a.npz")
    index = {"fps": 30.0, "clips": [{"name": "a", "file": "clips/a.npz", "style": "default", "split": "train",
                                     "source": "synthetic", "mirrored": False, "num_frames": t}]}
    (tmp_path / "index.json").write_text(json.dumps(index))
    code = main(["train", "generator", "--library", str(tmp_path), "-o", str(tmp_path / "out"), "--steps", "2"])
    err = capsys.readouterr().err
    assert code == 1, err
    assert "held-out" in err and "'test' split has no clips" in err, err
