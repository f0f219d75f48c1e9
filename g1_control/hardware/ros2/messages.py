"""ROS 2 message types as Cyclone DDS structs, named as ROS 2's middleware names them on the wire.

Member names and order follow the ROS 2 message definitions (geometry_msgs, sensor_msgs, nav_msgs,
tf2_msgs, std_msgs, builtin_interfaces); `final` with sequential ids, as ROS 2's generated IDL is
serialised by rmw_cyclonedds (plain CDR, no member headers). Importing this needs cyclonedds.
"""

# No `from __future__ import annotations`: Cyclone resolves these annotations at run time.

from dataclasses import dataclass, field

from cyclonedds.idl import IdlStruct
from cyclonedds.idl.annotations import autoid, final
from cyclonedds.idl.types import array, float64, int32, sequence, uint32

TOPIC_PREFIX = "rt/"
"""ROS 2 topics on DDS: `cmd_vel` is `rt/cmd_vel`."""


def dds_type(package: str, name: str) -> str:
    """`geometry_msgs`, `Twist` -> `geometry_msgs::msg::dds_::Twist_`."""
    return f"{package}::msg::dds_::{name}_"


@dataclass
@final
@autoid("sequential")
class Time_(IdlStruct, typename="builtin_interfaces::msg::dds_::Time_"):
    sec: int32 = 0
    nanosec: uint32 = 0


@dataclass
@final
@autoid("sequential")
class Header_(IdlStruct, typename=dds_type("std_msgs", "Header")):
    stamp: Time_ = field(default_factory=Time_)
    frame_id: str = ""


@dataclass
@final
@autoid("sequential")
class Vector3_(IdlStruct, typename=dds_type("geometry_msgs", "Vector3")):
    x: float64 = 0.0
    y: float64 = 0.0
    z: float64 = 0.0


@dataclass
@final
@autoid("sequential")
class Point_(IdlStruct, typename=dds_type("geometry_msgs", "Point")):
    x: float64 = 0.0
    y: float64 = 0.0
    z: float64 = 0.0


@dataclass
@final
@autoid("sequential")
class Quaternion_(IdlStruct, typename=dds_type("geometry_msgs", "Quaternion")):
    x: float64 = 0.0
    y: float64 = 0.0
    z: float64 = 0.0
    w: float64 = 1.0


@dataclass
@final
@autoid("sequential")
class Twist_(IdlStruct, typename=dds_type("geometry_msgs", "Twist")):
    linear: Vector3_ = field(default_factory=Vector3_)
    angular: Vector3_ = field(default_factory=Vector3_)


@dataclass
@final
@autoid("sequential")
class Pose_(IdlStruct, typename=dds_type("geometry_msgs", "Pose")):
    position: Point_ = field(default_factory=Point_)
    orientation: Quaternion_ = field(default_factory=Quaternion_)


@dataclass
@final
@autoid("sequential")
class PoseStamped_(IdlStruct, typename=dds_type("geometry_msgs", "PoseStamped")):
    """A pose at the header's stamp, in the header's frame (motion capture, SLAM: the external pose
    input, g1_control/estimation/external_pose.py)."""

    header: Header_ = field(default_factory=Header_)
    pose: Pose_ = field(default_factory=Pose_)


@dataclass
@final
@autoid("sequential")
class ObjectPoses_(IdlStruct, typename="g1_msgs::msg::dds_::ObjectPoses_"):
    """This project's own type (no ROS 2 standard fits): named objects seen at the header's stamp, each
    pose in the robot's heading frame (frame_id 'heading': origin at the pelvis, x forward along its
    heading, z up), as a perception system (e.g. AprilTags) reports them. names[i] goes with poses[i]."""

    header: Header_ = field(default_factory=Header_)
    names: sequence[str] = field(default_factory=list)
    poses: sequence[Pose_] = field(default_factory=list)


@dataclass
@final
@autoid("sequential")
class PlatformPoses_(IdlStruct, typename="g1_msgs::msg::dds_::PlatformPoses_"):
    """This project's own type, beside ObjectPoses_ (which it leaves as it was, so publishers and readers
    of boxes alone keep working; platforms go on a topic of their own: topics.PLATFORMS_SUFFIX): platforms
    (steps) seen at the header's stamp, in the robot's heading frame (frame_id 'heading'). poses[i]: the
    centre of names[i]'s top face and its yaw; sizes[i]: its footprint along its own x and y, and in z
    its height above the floor it stands on (m)."""

    header: Header_ = field(default_factory=Header_)
    names: sequence[str] = field(default_factory=list)
    poses: sequence[Pose_] = field(default_factory=list)
    sizes: sequence[Vector3_] = field(default_factory=list)


@dataclass
@final
@autoid("sequential")
class PoseWithCovariance_(IdlStruct, typename=dds_type("geometry_msgs", "PoseWithCovariance")):
    pose: Pose_ = field(default_factory=Pose_)
    covariance: array[float64, 36] = field(default_factory=lambda: [0.0] * 36)


@dataclass
@final
@autoid("sequential")
class TwistWithCovariance_(IdlStruct, typename=dds_type("geometry_msgs", "TwistWithCovariance")):
    twist: Twist_ = field(default_factory=Twist_)
    covariance: array[float64, 36] = field(default_factory=lambda: [0.0] * 36)


@dataclass
@final
@autoid("sequential")
class Odometry_(IdlStruct, typename=dds_type("nav_msgs", "Odometry")):
    header: Header_ = field(default_factory=Header_)
    child_frame_id: str = ""
    pose: PoseWithCovariance_ = field(default_factory=PoseWithCovariance_)
    twist: TwistWithCovariance_ = field(default_factory=TwistWithCovariance_)


@dataclass
@final
@autoid("sequential")
class JointState_(IdlStruct, typename=dds_type("sensor_msgs", "JointState")):
    header: Header_ = field(default_factory=Header_)
    name: sequence[str] = field(default_factory=list)
    position: sequence[float64] = field(default_factory=list)
    velocity: sequence[float64] = field(default_factory=list)
    effort: sequence[float64] = field(default_factory=list)


@dataclass
@final
@autoid("sequential")
class Transform_(IdlStruct, typename=dds_type("geometry_msgs", "Transform")):
    translation: Vector3_ = field(default_factory=Vector3_)
    rotation: Quaternion_ = field(default_factory=Quaternion_)


@dataclass
@final
@autoid("sequential")
class TransformStamped_(IdlStruct, typename=dds_type("geometry_msgs", "TransformStamped")):
    header: Header_ = field(default_factory=Header_)
    child_frame_id: str = ""
    transform: Transform_ = field(default_factory=Transform_)


@dataclass
@final
@autoid("sequential")
class TFMessage_(IdlStruct, typename=dds_type("tf2_msgs", "TFMessage")):
    transforms: sequence[TransformStamped_] = field(default_factory=list)


def seconds(time: Time_) -> float:
    """A builtin_interfaces/Time in seconds."""
    return time.sec + time.nanosec * 1e-9


def stamp(t_s: float) -> Time_:
    """builtin_interfaces/Time of `t_s` seconds (the loop's clock)."""
    sec = int(t_s // 1)
    return Time_(sec, min(round((t_s - sec) * 1e9), 999_999_999))
