import numpy as np
import pytest
from test_motion_clip import make_clip

from g1_control.motion.exceptions import InvalidClipError
from g1_control.motion.interpolation import resample_times
from g1_control.motion.resample import resample


def test_double_rate_keeps_original_frames_and_interpolates_between():
    clip = make_clip(t=11)
    fine = resample(clip, 60.0)
    assert fine.num_frames == 21 and fine.fps == 60.0
    np.testing.assert_allclose(fine.joint_pos_rad[::2], clip.joint_pos_rad, atol=1e-12)
    np.testing.assert_allclose(fine.joint_pos_rad[1], 0.5 * (clip.joint_pos_rad[0] + clip.joint_pos_rad[1]), atol=1e-12)
    # root yaw grows linearly in make_clip, so slerp's midpoint is the mean yaw
    yaw = 2 * np.arctan2(fine.root_quat_wxyz[:, 3], fine.root_quat_wxyz[:, 0])
    np.testing.assert_allclose(yaw, np.linspace(0, 0.5, 21), atol=1e-12)
    assert fine.duration_s == pytest.approx(clip.duration_s)


def test_round_trip_to_a_higher_rate_and_back_is_exact_on_joints():
    clip = make_clip(t=16)
    back = resample(resample(clip, 90.0), 30.0)
    np.testing.assert_allclose(back.joint_pos_rad, clip.joint_pos_rad, atol=1e-12)
    np.testing.assert_allclose(back.body_pos_w_m, clip.body_pos_w_m, atol=1e-12)


def test_times_and_bad_rate():
    np.testing.assert_allclose(resample_times(31, 30.0, 50.0), np.arange(51) / 50.0)
    with pytest.raises(InvalidClipError, match="to fps -1"):
        resample(make_clip(), -1.0)
