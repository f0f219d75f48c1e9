"""Clips from other retargeters: holosoma result npz (qpos) and GMR pickles."""

import pickle

import numpy as np
import pytest

from g1_control.motion.clip import MotionClip
from g1_control.motion.exceptions import MotionFormatError
from g1_control.motion.formats.dispatch import load_motion
from g1_control.robot import g1


def _trajectory(t: int = 12):
    rng = np.random.default_rng(3)
    root = np.c_[np.linspace(0, 0.3, t), np.zeros(t), np.full(t, 0.78)]
    yaw = np.linspace(0, 0.4, t)
    quat_wxyz = np.c_[np.cos(yaw / 2), np.zeros(t), np.zeros(t), np.sin(yaw / 2)]
    joints = np.asarray(g1.DEFAULT_Q_RAD) + 0.05 * rng.standard_normal((t, g1.NUM_JOINTS))
    return root, quat_wxyz, joints


def test_holosoma_qpos_npz_with_and_without_an_object(tmp_path):
    root, quat, joints = _trajectory()
    path = tmp_path / "climb_original.npz"
    np.savez(path, qpos=np.c_[root, quat, joints], human_joints=np.zeros((12, 5, 3)), fps=30, cost=1.0)
    clip = load_motion(path)
    assert isinstance(clip, MotionClip) and clip.fps == 30.0 and clip.num_frames == 12
    np.testing.assert_array_equal(clip.joint_pos_rad, joints)
    np.testing.assert_array_equal(clip.root_quat_wxyz, quat)
    with_object = tmp_path / "lift_original.npz"
    np.savez(with_object, qpos=np.c_[root, quat, joints, np.zeros((12, 3)), np.tile([1.0, 0, 0, 0], (12, 1))])
    np.testing.assert_array_equal(load_motion(with_object).joint_pos_rad, joints)
    bad = tmp_path / "bad.npz"
    np.savez(bad, qpos=np.zeros((12, 30)))
    with pytest.raises(MotionFormatError, match=r"qpos has shape \(12, 30\); expected \(T, 36\)"):
        load_motion(bad)


def test_gmr_pickle(tmp_path):
    root, quat, joints = _trajectory()
    path = tmp_path / "walk.pkl"
    with path.open("wb") as f:
        pickle.dump({"fps": 30, "root_pos": root, "root_rot": quat[:, [1, 2, 3, 0]], "dof_pos": joints,
                     "local_body_pos": None, "link_body_list": None}, f)
    clip = load_motion(path)
    np.testing.assert_allclose(clip.root_quat_wxyz, quat)
    np.testing.assert_array_equal(clip.joint_pos_rad, joints)
    assert clip.fps == 30.0


class _Sneaky:
    def __reduce__(self):
        return (print, ("this must not run",))


def test_gmr_reader_runs_no_code_from_a_pickle(tmp_path, capsys):
    path = tmp_path / "evil.pkl"
    path.write_bytes(pickle.dumps({"root_pos": _Sneaky()}))
    with pytest.raises(MotionFormatError, match="refusing to load builtins.print"):
        load_motion(path)
    assert "must not run" not in capsys.readouterr().out
