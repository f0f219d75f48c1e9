"""ROS 2 message types on Cyclone DDS: ROS 2's wire names and plain-CDR bytes, checked by hand."""

from __future__ import annotations

import struct

from g1_control.hardware.ros2 import messages as m

CDR_LE = b"\x00\x01\x00\x00"  # encapsulation: plain CDR, little endian


def test_type_names_are_ros2s_dds_names():
    assert m.Twist_.__idl_typename__ == "geometry_msgs::msg::dds_::Twist_"
    assert m.JointState_.__idl_typename__ == "sensor_msgs::msg::dds_::JointState_"
    assert m.Odometry_.__idl_typename__ == "nav_msgs::msg::dds_::Odometry_"
    assert m.TFMessage_.__idl_typename__ == "tf2_msgs::msg::dds_::TFMessage_"
    assert m.Header_.__idl_typename__ == "std_msgs::msg::dds_::Header_"
    assert m.Time_.__idl_typename__ == "builtin_interfaces::msg::dds_::Time_"


def test_a_twist_is_six_doubles():
    twist = m.Twist_(m.Vector3_(0.5, -0.25, 0.0), m.Vector3_(0.0, 0.0, 1.5))
    assert twist.serialize() == CDR_LE + struct.pack("<6d", 0.5, -0.25, 0.0, 0.0, 0.0, 1.5)


def test_a_joint_state_is_header_then_four_sequences():
    msg = m.JointState_(m.Header_(m.Time_(12, 500), "pelvis"), ["a", "bc"], [1.0], [], [2.0])
    body = (struct.pack("<iI", 12, 500) + struct.pack("<I", 7) + b"pelvis\x00"  # Time, frame_id with its NUL
            + b"\x00"  # pad to 4
            + struct.pack("<I", 2) + struct.pack("<I", 2) + b"a\x00" + b"\x00\x00" + struct.pack("<I", 3) + b"bc\x00"
            + b"\x00"  # pad to 4 (sequence length)
            + struct.pack("<I", 1) + b"\x00" * 4 + struct.pack("<d", 1.0)  # doubles align to 8
            + struct.pack("<I", 0)
            + struct.pack("<I", 1) + struct.pack("<d", 2.0))
    assert msg.serialize() == CDR_LE + body
    assert m.JointState_.deserialize(msg.serialize()) == msg


def test_stamps_split_seconds_and_nanoseconds():
    assert m.stamp(12.25) == m.Time_(12, 250_000_000)
    assert m.stamp(0.0) == m.Time_(0, 0)
    assert m.stamp(3.9999999999) == m.Time_(3, 999_999_999)


def test_pose_stamped_is_ros2s_and_object_poses_is_our_own_type():
    assert m.PoseStamped_.__idl_typename__ == "geometry_msgs::msg::dds_::PoseStamped_"
    assert m.ObjectPoses_.__idl_typename__ == "g1_msgs::msg::dds_::ObjectPoses_"
    msg = m.PoseStamped_(m.Header_(m.Time_(3, 5), "mocap"), m.Pose_(m.Point_(1.0, 2.0, 3.0), m.Quaternion_(0, 0, 0, 1)))
    assert m.PoseStamped_.deserialize(msg.serialize()) == msg
    assert msg.serialize() == CDR_LE + (struct.pack("<iI", 3, 5) + struct.pack("<I", 6) + b"mocap\x00" + b"\x00" * 6  # doubles align to 8
                                        + struct.pack("<7d", 1.0, 2.0, 3.0, 0.0, 0.0, 0.0, 1.0))
    seen = m.ObjectPoses_(m.Header_(m.Time_(1, 0), "heading"), ["box"], [m.Pose_()])
    assert m.ObjectPoses_.deserialize(seen.serialize()) == seen
    assert m.seconds(m.stamp(12.25)) == 12.25


def test_platform_poses_is_our_own_type_beside_object_poses_on_a_topic_of_its_own():
    from g1_control.hardware.ros2.topics import PLATFORMS_SUFFIX

    assert m.PlatformPoses_.__idl_typename__ == "g1_msgs::msg::dds_::PlatformPoses_"
    assert [f for f in m.ObjectPoses_.__annotations__] == ["header", "names", "poses"]  # boxes' type unchanged
    seen = m.PlatformPoses_(m.Header_(m.Time_(1, 5), "heading"), ["step"],
                            [m.Pose_(m.Point_(1.0, 0.2, -0.6), m.Quaternion_(0.0, 0.0, 0.1, 0.995))],
                            [m.Vector3_(0.7, 1.2, 0.15)])
    assert m.PlatformPoses_.deserialize(seen.serialize()) == seen
    assert PLATFORMS_SUFFIX == "/platforms"
