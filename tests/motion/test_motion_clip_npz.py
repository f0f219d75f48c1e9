import numpy as np
import pytest
from test_motion_clip import make_clip

from g1_control.motion.exceptions import MotionFormatError
from g1_control.motion.formats.clip_npz import read_clip_npz, write_clip_npz
from g1_control.robot import g1


def test_npz_round_trip_is_exact(tmp_path):
    clip = make_clip(seed=5)
    clip.style = "wave"
    write_clip_npz(clip, tmp_path / "c.npz")
    back = read_clip_npz(tmp_path / "c.npz")
    assert back.equals(clip)  # every array bit for bit, names, fps, source, style, tags
    with np.load(tmp_path / "c.npz") as data:
        assert tuple(data["body_names"]) == clip.body_names and tuple(data["joint_names"]) == g1.JOINT_NAMES


def test_unnamed_file_with_permuted_bodies_is_identified(tmp_path):
    clip = make_clip(seed=6)
    perm = np.random.default_rng(0).permutation(len(clip.body_names))
    perm = np.concatenate([[0], perm[perm != 0]])  # body 0 stays the pelvis, as in both projects
    np.savez(tmp_path / "foreign.npz", fps=clip.fps, joint_pos=clip.joint_pos_rad, joint_vel=clip.joint_vel_radps,
             body_pos_w=clip.body_pos_w_m[:, perm], body_quat_w=clip.body_quat_wxyz[:, perm],
             body_lin_vel_w=clip.body_lin_vel_w_mps[:, perm], body_ang_vel_w=clip.body_ang_vel_w_radps[:, perm])
    back = read_clip_npz(tmp_path / "foreign.npz")
    np.testing.assert_allclose(back.body_pos_w_m, clip.body_pos_w_m, atol=1e-12)
    np.testing.assert_allclose(back.joint_pos_rad, clip.joint_pos_rad)


def test_unnamed_file_in_another_joint_order_is_refused(tmp_path):
    clip = make_clip(seed=7)
    shuffled = clip.joint_pos_rad[:, ::-1]
    np.savez(tmp_path / "isaac.npz", fps=clip.fps, joint_pos=shuffled, joint_vel=clip.joint_vel_radps,
             body_pos_w=clip.body_pos_w_m, body_quat_w=clip.body_quat_wxyz,
             body_lin_vel_w=clip.body_lin_vel_w_mps, body_ang_vel_w=clip.body_ang_vel_w_radps)
    with pytest.raises(MotionFormatError, match="joint order is not g1.JOINT_NAMES"):
        read_clip_npz(tmp_path / "isaac.npz")


def test_missing_keys_are_listed(tmp_path):
    np.savez(tmp_path / "half.npz", fps=30.0, joint_pos=np.zeros((3, 29)))
    with pytest.raises(MotionFormatError, match=r"half.npz: missing keys \['joint_vel', 'body_pos_w'"):
        read_clip_npz(tmp_path / "half.npz")
