import numpy as np
import pytest

from g1_control.robot import g1


def test_joint_order_is_unitree_order():
    assert g1.NUM_JOINTS == 29
    assert g1.JOINT_NAMES[0] == "left_hip_pitch_joint"
    assert g1.JOINT_NAMES[12:15] == ("waist_yaw_joint", "waist_roll_joint", "waist_pitch_joint")
    assert g1.JOINT_NAMES[28] == "right_wrist_yaw_joint"
    assert all(n.endswith("_joint") for n in g1.JOINT_NAMES)


def test_right_side_limits_mirror_left_for_roll_joints():
    i, j = g1.JOINT_INDEX["left_hip_roll_joint"], g1.JOINT_INDEX["right_hip_roll_joint"]
    assert g1.Q_MIN_RAD[j] == -g1.Q_MAX_RAD[i] and g1.Q_MAX_RAD[j] == -g1.Q_MIN_RAD[i]
    i, j = g1.JOINT_INDEX["left_shoulder_roll_joint"], g1.JOINT_INDEX["right_shoulder_roll_joint"]
    assert g1.Q_MIN_RAD[j] == -g1.Q_MAX_RAD[i]


def test_default_pose_inside_limits():
    assert np.all(g1.DEFAULT_Q_RAD >= g1.Q_MIN_RAD) and np.all(g1.DEFAULT_Q_RAD <= g1.Q_MAX_RAD)


def test_gains_reproduce_holosoma_policy_metadata():
    # kp/kd stored in holosoma's G1 ONNX metadata for hip pitch, hip roll, ankle, shoulder, wrist pitch.
    idx = [g1.JOINT_INDEX[n] for n in ("left_hip_pitch_joint", "left_hip_roll_joint",
                                       "left_ankle_pitch_joint", "left_shoulder_pitch_joint",
                                       "left_wrist_pitch_joint")]
    np.testing.assert_allclose(g1.KP_DEFAULT[idx], [40.179238471, 99.098427777, 28.501246196,
                                                    14.250623098, 16.778327481], rtol=1e-8)
    np.testing.assert_allclose(g1.KD_DEFAULT[idx], [2.557889765, 6.308801854, 1.814445687,
                                                    0.907222843, 1.068141502], rtol=1e-8)


def test_limits_are_the_urdf_limits():
    # One documented value per limit, the description's (issue 12): read from the URDF file itself.
    from g1_control.robot import description

    urdf = description.urdf_joint_limits()
    np.testing.assert_array_equal(g1.Q_MIN_RAD, urdf["lower"])
    np.testing.assert_array_equal(g1.Q_MAX_RAD, urdf["upper"])
    np.testing.assert_array_equal(g1.VELOCITY_LIMIT_RADPS, urdf["velocity"])
    np.testing.assert_array_equal(g1.EFFORT_LIMIT_NM, urdf["effort"])
    ankle, waist_roll = g1.JOINT_INDEX["left_ankle_pitch_joint"], g1.JOINT_INDEX["waist_roll_joint"]
    assert g1.VELOCITY_LIMIT_RADPS[ankle] == g1.VELOCITY_LIMIT_RADPS[waist_roll] == 30.0
    assert g1.EFFORT_LIMIT_NM[ankle] == g1.EFFORT_LIMIT_NM[waist_roll] == 35.0
    assert g1.EFFORT_LIMIT_NM[g1.JOINT_INDEX["left_knee_joint"]] == 139.0


def test_variants_by_mode_machine():
    assert g1.variant_for_mode_machine(5).num_dof == 29
    v23 = g1.variant_for_mode_machine(4)
    assert v23.num_dof == 23
    assert not v23.active_mask[g1.JOINT_INDEX["waist_roll_joint"]]
    with pytest.raises(ValueError, match="unknown G1 mode_machine 9"):
        g1.variant_for_mode_machine(9)


def test_constants_are_read_only():
    with pytest.raises(ValueError):
        g1.DEFAULT_Q_RAD[0] = 1.0
