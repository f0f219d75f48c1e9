import numpy as np
import pytest
from test_motion_clip import make_clip

from g1_control.motion.edit import concatenate, slice_clip
from g1_control.motion.exceptions import IncompatibleClipsError, InvalidClipError
from g1_control.motion.resample import resample


def test_slice_takes_frames_like_python():
    clip = make_clip(t=20)
    part = slice_clip(clip, 5, -5)
    assert part.num_frames == 10
    np.testing.assert_array_equal(part.joint_pos_rad, clip.joint_pos_rad[5:15])
    with pytest.raises(InvalidClipError, match=r"slice \[30:None\] .* is empty"):
        slice_clip(clip, 30)


def test_concatenate_aligns_each_start_with_the_previous_end():
    a, b = make_clip(t=10, seed=1), make_clip(t=12, seed=2)
    joined = concatenate([a, b])
    assert joined.num_frames == 22
    np.testing.assert_allclose(joined.root_pos_w_m[10, :2], a.root_pos_w_m[-1, :2], atol=1e-12)
    yaw = 2 * np.arctan2(joined.root_quat_wxyz[:, 3], joined.root_quat_wxyz[:, 0])
    assert yaw[10] == pytest.approx(yaw[9])
    np.testing.assert_array_equal(joined.joint_pos_rad[10:], b.joint_pos_rad)
    # bodies moved rigidly with the root
    rel_before = b.body_pos_w_m[:, 5] - b.body_pos_w_m[:, 0]
    rel_after = joined.body_pos_w_m[10:, 5] - joined.body_pos_w_m[10:, 0]
    np.testing.assert_allclose(np.linalg.norm(rel_after, axis=1), np.linalg.norm(rel_before, axis=1), atol=1e-12)


def test_concatenate_refuses_different_rates():
    with pytest.raises(IncompatibleClipsError, match="different fps"):
        concatenate([make_clip(), resample(make_clip(), 60.0)])
