import numpy as np
from test_motion_clip import make_clip

from g1_control.motion.clip import MotionClip
from g1_control.motion.mirror import joint_mirror_map, mirror
from g1_control.robot import g1


def test_mirror_twice_is_the_identity_exactly():
    clip = make_clip(seed=3)
    assert mirror(mirror(clip)).equals(clip)


def test_g1_sign_conventions():
    perm, sign = joint_mirror_map(g1.JOINT_NAMES)
    q = np.zeros(29)
    q[g1.JOINT_INDEX["left_hip_roll_joint"]] = 0.3
    q[g1.JOINT_INDEX["left_hip_pitch_joint"]] = -0.4
    q[g1.JOINT_INDEX["waist_yaw_joint"]] = 0.2
    q[g1.JOINT_INDEX["waist_pitch_joint"]] = 0.1
    m = sign * q[perm]
    assert m[g1.JOINT_INDEX["right_hip_roll_joint"]] == -0.3
    assert m[g1.JOINT_INDEX["right_hip_pitch_joint"]] == -0.4
    assert m[g1.JOINT_INDEX["waist_yaw_joint"]] == -0.2
    assert m[g1.JOINT_INDEX["waist_pitch_joint"]] == 0.1
    # the limits are mirror images, so a mirrored in-limit pose stays in limits
    np.testing.assert_allclose(np.sort(np.stack([sign * g1.Q_MIN_RAD[perm], sign * g1.Q_MAX_RAD[perm]]), axis=0),
                               np.stack([g1.Q_MIN_RAD, g1.Q_MAX_RAD]), atol=1e-9)


def test_mirrored_bodies_match_forward_kinematics_of_mirrored_joints():
    clip = make_clip(seed=4)
    m = mirror(clip)
    fk = MotionClip.from_joint_trajectory(m.fps, m.root_pos_w_m, m.root_quat_wxyz, m.joint_pos_rad)
    # the G1 description is left/right symmetric to ~1e-5 m
    np.testing.assert_allclose(fk.body_pos_w_m, m.body_pos_w_m, atol=1e-4)
    np.testing.assert_allclose(np.abs(np.sum(fk.body_quat_wxyz * m.body_quat_wxyz, axis=-1)), 1.0, atol=1e-6)
    assert (m.contacts == clip.contacts[:, ::-1]).all()
