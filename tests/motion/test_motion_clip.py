import numpy as np
import pinocchio as pin
import pytest

from g1_control.motion.clip import MotionClip
from g1_control.motion.exceptions import InvalidClipError
from g1_control.robot import description, g1


def make_clip(t: int = 20, seed: int = 0, fps: float = 30.0) -> MotionClip:
    rng = np.random.default_rng(seed)
    joints = np.clip(g1.DEFAULT_Q_RAD + 0.2 * np.sin(np.linspace(0, 3, t)[:, None] + rng.uniform(0, 6, 29)),
                     g1.Q_MIN_RAD, g1.Q_MAX_RAD)
    yaw = np.linspace(0, 0.5, t)
    quat = np.stack([np.cos(yaw / 2), np.zeros(t), np.zeros(t), np.sin(yaw / 2)], axis=1)
    root = np.stack([np.linspace(0, 0.5, t), 0.1 * np.sin(np.linspace(0, 3, t)), np.full(t, 0.78)], axis=1)
    return MotionClip.from_joint_trajectory(fps, root, quat, joints, source=f"synthetic{seed}", tags=("test",))


def test_bodies_are_the_pinocchio_forward_kinematics():
    clip = make_clip()
    model = description.pinocchio_model()
    data = model.createData()
    k = 7
    pin.framesForwardKinematics(model, data, description.pinocchio_q(clip.root_pos_w_m[k], clip.root_quat_wxyz[k],
                                                                     clip.joint_pos_rad[k]))
    for b in (0, 6, 22):
        placement = data.oMf[model.getFrameId(clip.body_names[b])]
        np.testing.assert_allclose(clip.body_pos_w_m[k, b], placement.translation, atol=1e-12)
        q = pin.Quaternion(placement.rotation)
        assert abs(abs(np.dot(clip.body_quat_wxyz[k, b], [q.w, q.x, q.y, q.z])) - 1.0) < 1e-12
    np.testing.assert_allclose(clip.body_pos_w_m[:, 0], clip.root_pos_w_m, atol=1e-12)


def test_velocities_are_differences_of_positions():
    clip = make_clip()
    np.testing.assert_allclose(clip.joint_vel_radps[5], (clip.joint_pos_rad[6] - clip.joint_pos_rad[4]) * 15.0)
    np.testing.assert_allclose(clip.body_lin_vel_w_mps[5, 0], (clip.root_pos_w_m[6] - clip.root_pos_w_m[4]) * 15.0)
    # root yaw rate 0.5 rad over 19 frames at 30 fps
    np.testing.assert_allclose(clip.body_ang_vel_w_radps[5, 0], [0, 0, 0.5 / 19 * 30], atol=1e-9)


def test_zero_frames_nan_and_shapes_are_named():
    clip = make_clip()
    with pytest.raises(InvalidClipError, match="has zero frames"):
        MotionClip.from_joint_trajectory(30, np.zeros((0, 3)), np.zeros((0, 4)), np.zeros((0, 29)), source="empty")
    bad = clip.copy()
    bad.joint_pos_rad[4, 2] = np.nan
    with pytest.raises(InvalidClipError, match="'synthetic0': joint_pos_rad has NaN or inf at frame 4"):
        bad.validate()
    bad = clip.copy()
    bad.contacts = bad.contacts[:, :1]
    with pytest.raises(InvalidClipError, match=r"contacts has shape \(20, 1\); expected \(20, 2\)"):
        bad.validate()
    bad = clip.copy()
    bad.root_quat_wxyz[3] *= 2
    with pytest.raises(InvalidClipError, match="frame 3 has norm 2.0000"):
        bad.validate()


def test_copy_is_deep_and_equals_compares_everything():
    clip = make_clip()
    other = clip.copy()
    assert other.equals(clip)
    other.joint_pos_rad[0, 0] += 1e-9
    assert not other.equals(clip)
    assert other.equals(clip, atol=1e-8)
    assert clip.duration_s == pytest.approx(19 / 30)
