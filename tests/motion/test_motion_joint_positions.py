import pickle

import numpy as np
import pytest
import torch

from g1_control.motion.exceptions import InvalidClipError, MotionFormatError
from g1_control.motion.formats.joint_positions import read_npy, read_omomo_pt
from g1_control.motion.skeletons import HOLOSOMA_MOCAP, SMPLH


def test_npy_with_53_joints_is_the_holosoma_mocap_skeleton(tmp_path):
    pos = np.random.default_rng(0).standard_normal((5, 53, 3)).astype(np.float32)
    np.save(tmp_path / "climb.npy", pos)
    motion = read_npy(tmp_path / "climb.npy")
    assert motion.joint_names == HOLOSOMA_MOCAP.joints and motion.fps == 120.0 and motion.height_m == 1.78
    np.testing.assert_array_equal(motion.positions_w_m, pos.astype(float))


def test_npy_shape_joint_count_and_nan_errors(tmp_path):
    np.save(tmp_path / "flat.npy", np.zeros((5, 9)))
    with pytest.raises(MotionFormatError, match=r"flat.npy: array has shape \(5, 9\); expected \(T, J, 3\)"):
        read_npy(tmp_path / "flat.npy")
    np.save(tmp_path / "odd.npy", np.zeros((5, 7, 3)))
    with pytest.raises(MotionFormatError, match="7 joints match no known skeleton"):
        read_npy(tmp_path / "odd.npy")
    with pytest.raises(MotionFormatError, match="7 joints in the file but 2 names"):
        read_npy(tmp_path / "odd.npy", joint_names=("a", "b"))
    pos = np.zeros((5, 53, 3))
    pos[3, 10, 0] = np.nan
    np.save(tmp_path / "nan.npy", pos)
    with pytest.raises(InvalidClipError, match="'nan.npy': NaN or inf at frame 3"):
        read_npy(tmp_path / "nan.npy")


def test_omomo_pt_columns_and_subject_height(tmp_path):
    rows = torch.zeros(4, 591)
    joints = torch.arange(52 * 3, dtype=torch.float32).reshape(1, 52, 3).repeat(4, 1, 1) / 100
    rows[:, 162:318] = joints.reshape(4, -1)
    folder = tmp_path / "OMOMO_new"
    folder.mkdir()
    torch.save(rows.requires_grad_(), folder / "sub7_box_001.pt")
    with (tmp_path / "height_dict.pkl").open("wb") as fh:
        pickle.dump({"sub7": np.float32(1.8)}, fh)
    motion = read_omomo_pt(folder / "sub7_box_001.pt")
    assert motion.joint_names == SMPLH.joints and motion.fps == 30.0
    assert motion.height_m == pytest.approx(1.8)
    np.testing.assert_allclose(motion.positions_w_m, joints.numpy(), atol=1e-7)
    torch.save(torch.zeros(3, 100), folder / "short.pt")
    with pytest.raises(MotionFormatError, match=r"short.pt: tensor has shape \(3, 100\)"):
        read_omomo_pt(folder / "short.pt")
