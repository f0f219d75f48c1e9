"""geometry_msgs/PoseStamped over Cyclone DDS: a reader (the external pose input) and a writer
(g1 sim-robot's motion capture, tests); perception's ObjectPoses_ (boxes) and PlatformPoses_
(platforms, on the perception topic + PLATFORMS_SUFFIX), read and written the same way.

Stamps are the publisher's wall clock (ROS time: seconds since the epoch). The reader hands each
pose on with the wall-clock age it had when it was read, so a consumer can place it on its own clock
(the loop's monotonic or simulated time): stamp_on_my_clock = my_now - age. On one computer the
clocks agree; across computers they must be synchronised (chrony/PTP), or poses are refused as
stale or from the future (estimation/external_pose.py).
"""

from __future__ import annotations

import math
import re
import time
from dataclasses import dataclass

from g1_control.hardware.links.dds import DdsEntities, domain_participant

HISTORY_DEPTH = 64
"""Poses a reader keeps between takes (0.64 s of a 100 Hz motion capture, read every loop tick)."""
PLATFORMS_SUFFIX = "/platforms"
"""PlatformPoses_ go on the perception topic with this appended (perception/objects -> perception/objects/platforms)."""
TOPIC_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*(/[A-Za-z_][A-Za-z0-9_]*)*$")


def check_topic_name(name: object) -> str | None:
    """Why `name` is not a ROS 2 topic name as this project writes it ('mocap/pose'), or None."""
    if not isinstance(name, str) or not TOPIC_NAME.match(name) or name.startswith("rt/"):
        return (f"{name!r} is not a ROS 2 topic name (letters, digits and _ in /-separated parts, no leading "
                "/ and no rt/ prefix, e.g. mocap/pose)")
    return None


@dataclass(frozen=True)
class PoseReading:
    """One PoseStamped as read: the stamp (publisher's wall clock), its age when read, the pose."""

    stamp_s: float
    age_s: float
    x_m: float
    y_m: float
    z_m: float
    quat_wxyz: tuple[float, float, float, float]
    frame_id: str

    @property
    def yaw_rad(self) -> float:
        w, x, y, z = self.quat_wxyz
        return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


def _group_qos(partition: str | None):
    from cyclonedds.qos import Policy, Qos

    return Qos(Policy.Partition([partition])) if partition else None


class PoseTopicReader:
    """Takes PoseStamped samples from rt/<topic> (no thread: take() drains what arrived)."""

    def __init__(self, interface: str, domain: int, topic: str, partition: str | None = None):
        from cyclonedds.qos import Policy, Qos
        from cyclonedds.sub import DataReader, Subscriber
        from cyclonedds.topic import Topic

        from g1_control.hardware.ros2 import messages as m

        problem = check_topic_name(topic)
        if problem:
            raise ValueError(f"external pose topic: {problem}")
        self.topic = topic
        self._dds = DdsEntities()  # made, taken and deleted under the process-wide DDS entity lock
        with self._dds.lock():
            participant = self._dds.add("participant", domain_participant(interface, domain))
            # Every pose since the last take (DDS keeps only the latest by default): a late pose and a
            # fresher one arriving together are each judged (the fusion refuses the stale one by name).
            self._dds.add("reader", DataReader(Subscriber(participant, qos=_group_qos(partition)),
                                               Topic(participant, m.TOPIC_PREFIX + topic, m.PoseStamped_),
                                               qos=Qos(Policy.History.KeepLast(HISTORY_DEPTH))))
        self._seconds = m.seconds
        self.received = 0

    def take(self) -> list[PoseReading]:
        now = time.time()
        out = []
        for msg in self._dds.take("reader", HISTORY_DEPTH):  # [] once closed
            if not hasattr(msg, "pose"):
                continue  # a sample-less info (writer gone)
            stamp = self._seconds(msg.header.stamp)
            p, q = msg.pose.position, msg.pose.orientation
            out.append(PoseReading(stamp, now - stamp, p.x, p.y, p.z, (q.w, q.x, q.y, q.z), msg.header.frame_id))
        self.received += len(out)
        return out

    def close(self) -> None:
        self._dds.close()


class PoseTopicWriter:
    """Writes PoseStamped samples to rt/<topic>."""

    def __init__(self, interface: str, domain: int, topic: str, partition: str | None = None,
                 frame_id: str = "mocap"):
        from cyclonedds.pub import DataWriter, Publisher
        from cyclonedds.topic import Topic

        from g1_control.hardware.ros2 import messages as m

        problem = check_topic_name(topic)
        if problem:
            raise ValueError(f"pose topic: {problem}")
        self._m = m
        self.frame_id = frame_id
        self._dds = DdsEntities()  # made, written and deleted under the process-wide DDS entity lock
        with self._dds.lock():
            participant = self._dds.add("participant", domain_participant(interface, domain))
            self._dds.add("writer", DataWriter(Publisher(participant, qos=_group_qos(partition)),
                                               Topic(participant, m.TOPIC_PREFIX + topic, m.PoseStamped_)))
        self.sent = 0

    def write(self, stamp_s: float, position_m, quat_wxyz) -> None:
        m = self._m
        x, y, z = (float(v) for v in position_m)
        w, qx, qy, qz = (float(v) for v in quat_wxyz)
        if self._dds.write("writer", m.PoseStamped_(m.Header_(m.stamp(stamp_s), self.frame_id),
                                                    m.Pose_(m.Point_(x, y, z), m.Quaternion_(qx, qy, qz, w)))):
            self.sent += 1  # not once closed

    def close(self) -> None:
        self._dds.close()


@dataclass(frozen=True)
class ObjectsReading:
    """One ObjectPoses as read: stamp (publisher's wall clock), its age when read, name -> (xyz, quat wxyz)
    in the robot's heading frame."""

    stamp_s: float
    age_s: float
    objects: dict[str, tuple[tuple[float, float, float], tuple[float, float, float, float]]]


@dataclass(frozen=True)
class PlatformsReading:
    """One PlatformPoses as read: stamp (publisher's wall clock), its age when read, name -> (top centre xyz,
    quat wxyz, size: footprint x, y and height) in the robot's heading frame."""

    stamp_s: float
    age_s: float
    platforms: dict[str, tuple[tuple[float, float, float], tuple[float, float, float, float],
                               tuple[float, float, float]]]


def _perception_reader(interface: str, domain: int, topic: str, partition: str | None, message):
    """The participant and DataReader ("reader") of `message` samples on rt/<topic> (keeps HISTORY_DEPTH between
    takes), made under the process-wide DDS entity lock."""
    from cyclonedds.qos import Policy, Qos
    from cyclonedds.sub import DataReader, Subscriber
    from cyclonedds.topic import Topic

    from g1_control.hardware.links.dds import domain_participant
    from g1_control.hardware.ros2 import messages as m

    problem = check_topic_name(topic)
    if problem:
        raise ValueError(f"perception topic: {problem}")
    entities = DdsEntities()
    with entities.lock():
        participant = entities.add("participant", domain_participant(interface, domain))
        entities.add("reader", DataReader(Subscriber(participant, qos=_group_qos(partition)),
                                          Topic(participant, m.TOPIC_PREFIX + topic, message),
                                          qos=Qos(Policy.History.KeepLast(HISTORY_DEPTH))))
    return entities


def _perception_writer(interface: str, domain: int, topic: str, partition: str | None, message):
    """The participant and DataWriter ("writer") of `message` samples on rt/<topic>, made under the process-wide
    DDS entity lock."""
    from cyclonedds.pub import DataWriter, Publisher
    from cyclonedds.topic import Topic

    from g1_control.hardware.links.dds import domain_participant
    from g1_control.hardware.ros2 import messages as m

    problem = check_topic_name(topic)
    if problem:
        raise ValueError(f"perception topic: {problem}")
    entities = DdsEntities()
    with entities.lock():
        participant = entities.add("participant", domain_participant(interface, domain))
        entities.add("writer", DataWriter(Publisher(participant, qos=_group_qos(partition)),
                                          Topic(participant, m.TOPIC_PREFIX + topic, message)))
    return entities


def _xyz(p) -> tuple[float, float, float]:
    return (p.x, p.y, p.z)


def _wxyz(q) -> tuple[float, float, float, float]:
    return (q.w, q.x, q.y, q.z)


class _PerceptionReader:
    """Takes one perception message type from rt/<topic>; subclasses turn a sample into a reading."""

    _message = ""  # the message class's name in hardware/ros2/messages.py
    _field = ""  # a field only that message has (samples of another type on the topic are skipped)

    def __init__(self, interface: str, domain: int, topic: str, partition: str | None = None):
        from g1_control.hardware.ros2 import messages as m

        self._dds = _perception_reader(interface, domain, topic, partition, getattr(m, self._message))
        self._seconds = m.seconds

    def take(self) -> list:
        now = time.time()
        out = []
        for msg in self._dds.take("reader", HISTORY_DEPTH):  # [] once closed
            if not hasattr(msg, self._field):
                continue
            stamp = self._seconds(msg.header.stamp)
            out.append(self._reading(stamp, now - stamp, msg))
        return out

    def _reading(self, stamp_s: float, age_s: float, msg):
        raise NotImplementedError

    def close(self) -> None:
        self._dds.close()


class ObjectPosesReader(_PerceptionReader):
    """Takes ObjectPoses samples from rt/<topic> (perception: objects in the robot's heading frame)."""

    _message, _field = "ObjectPoses_", "poses"

    def take(self) -> list[ObjectsReading]:
        return super().take()

    def _reading(self, stamp_s: float, age_s: float, msg) -> ObjectsReading:
        return ObjectsReading(stamp_s, age_s, {name: (_xyz(p.position), _wxyz(p.orientation))
                                               for name, p in zip(msg.names, msg.poses)})


class PlatformPosesReader(_PerceptionReader):
    """Takes PlatformPoses samples from rt/<topic> (perception: platforms in the robot's heading frame;
    `topic` is the perception topic with PLATFORMS_SUFFIX)."""

    _message, _field = "PlatformPoses_", "sizes"

    def take(self) -> list[PlatformsReading]:
        return super().take()

    def _reading(self, stamp_s: float, age_s: float, msg) -> PlatformsReading:
        return PlatformsReading(stamp_s, age_s, {name: (_xyz(p.position), _wxyz(p.orientation), _xyz(size))
                                                 for name, p, size in zip(msg.names, msg.poses, msg.sizes)})


class _PerceptionWriter:
    """Writes one perception message type to rt/<topic>, stamped, in the heading frame."""

    _message = ""  # the message class's name in hardware/ros2/messages.py

    def __init__(self, interface: str, domain: int, topic: str, partition: str | None = None):
        from g1_control.hardware.ros2 import messages as m

        self._m = m
        self._dds = _perception_writer(interface, domain, topic, partition, getattr(m, self._message))
        self.sent = 0

    def _send(self, stamp_s: float, *fields) -> None:
        m = self._m
        if self._dds.write("writer", getattr(m, self._message)(m.Header_(m.stamp(stamp_s), "heading"), *fields)):
            self.sent += 1  # not once closed

    def close(self) -> None:
        self._dds.close()


class ObjectPosesWriter(_PerceptionWriter):
    """Writes ObjectPoses samples to rt/<topic> (g1 sim-robot --scene's perception)."""

    _message = "ObjectPoses_"

    def write(self, stamp_s: float, objects: dict) -> None:
        """objects: name -> (position xyz, quat wxyz) in the robot's heading frame."""
        self._send(stamp_s, list(objects), [_pose(self._m, pos, quat) for pos, quat in objects.values()])


class PlatformPosesWriter(_PerceptionWriter):
    """Writes PlatformPoses samples to rt/<topic> (g1 sim-robot --scene's perception of the scene's platforms)."""

    _message = "PlatformPoses_"

    def write(self, stamp_s: float, platforms: dict) -> None:
        """platforms: name -> (top centre xyz, quat wxyz, size: footprint x, y and height) in the heading frame."""
        m = self._m
        self._send(stamp_s, list(platforms), [_pose(m, pos, quat) for pos, quat, _ in platforms.values()],
                   [m.Vector3_(*(float(v) for v in size)) for _, _, size in platforms.values()])


def _pose(m, pos, quat):
    x, y, z = (float(v) for v in pos)
    w, qx, qy, qz = (float(v) for v in quat)
    return m.Pose_(m.Point_(x, y, z), m.Quaternion_(qx, qy, qz, w))


__all__ = ["PLATFORMS_SUFFIX", "ObjectPosesReader", "ObjectPosesWriter", "ObjectsReading", "PlatformPosesReader",
           "PlatformPosesWriter", "PlatformsReading", "PoseReading", "PoseTopicReader", "PoseTopicWriter", "check_topic_name"]
