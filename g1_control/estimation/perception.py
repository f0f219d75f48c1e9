"""Where things are, from perception: named objects seen in the robot's heading frame (origin at the
pelvis, x along its heading; e.g. AprilTags on boxes), stamped when seen, placed in the scene frame
with the robot's own estimate at that stamp (the Localiser's track: latency compensated), so the scene
follows the objects as the robot moves. Frames older than max_age_s are refused (stale), as are frames
stamped before the estimate's track or after now (no pose to place them with). An object that stays
put is where the mean of its last AVERAGE_FRAMES placements says (a single frame carries the noise of
one measurement: 2 cm per axis and 3 deg of heading put a box ~3.5 cm off at 0.5 m, and a grasp planned
on that lifted the box 6.6 cm instead of 11 and the robot fell carrying it, over DDS); one placed more
than MOVED_M from that mean starts the average over (it was moved).

    perception = ObjectPerception(PerceptionConfig(interface="lo", max_age_s=0.5), source)
    perception.update(now_s, localiser.pose_at)     # every estimator tick, after the localiser
    perception.positions["box"]                      # (x, y, z) in the scene frame

Platforms (steps) arrive the same way on a topic of their own (the perception topic + /platforms:
PlatformPoses_, the centre of each top face with its yaw, and its footprint and height), stamped,
refused by the same rules, averaged the same way, and kept as scene Platforms (`platforms`) in the
scene frame; a sighting that is not a platform the scene could hold (a size or height out of range, a
bad name, a number that is not finite) is refused by name as invalid.

    perception = ObjectPerception(config, source, DdsPlatformSource(reader))
    perception.platforms["step"]                     # scene.Platform where perception sees it
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Generic, Protocol, TypeVar

import numpy as np

from g1_control.errors import LaunchFileError
from g1_control.rotations import wrap_angle, yaw_of
from g1_control.scene import Platform
from g1_control.types import WorldPose


@dataclass
class PerceptionConfig:
    """launch file `estimation.perception`: the topic of object poses (g1 sim-robot --scene publishes one),
    and beside it the topic of platforms (`platform_topic`)."""

    topic: str = "perception/objects"
    interface: str | None = None
    domain: int = 0
    partition: str | None = None
    """Default: the robot link's (backend.partition)."""
    max_age_s: float = 0.5

    @property
    def platform_topic(self) -> str:
        """Where platforms arrive: the topic + /platforms (PlatformPoses_, hardware/ros2/messages.py)."""
        from g1_control.hardware.ros2.topics import PLATFORMS_SUFFIX

        return self.topic + PLATFORMS_SUFFIX

    def validate(self, where: str) -> None:
        from g1_control.hardware.ros2.topics import check_topic_name

        if not isinstance(self.interface, str) or not self.interface:
            raise LaunchFileError(f"{where}.interface: a perception input must name the network interface of its "
                                  "publisher (lo for this computer, e.g. g1 sim-robot --scene)")
        problem = check_topic_name(self.topic)
        if problem:
            raise LaunchFileError(f"{where}.topic: {problem}")
        if not 0 <= self.domain <= 232:
            raise LaunchFileError(f"{where}.domain: {self.domain} is not a DDS domain id (0..232)")
        if not (math.isfinite(self.max_age_s) and 0 < self.max_age_s <= 2.0):
            raise LaunchFileError(f"{where}.max_age_s: {self.max_age_s} is outside (0, 2] s")


AVERAGE_FRAMES = 20
"""Placements of an object that stays put averaged (2 s of a 10 Hz perception): the noise / ~4.5."""
MOVED_M = 0.25
"""A placement this far from an object's mean is the object moved (heading noise of 3 deg alone puts a
box 21 cm sideways at 4 m)."""

Objects = dict[str, tuple[tuple[float, float, float], tuple[float, float, float, float]]]
Platforms = dict[str, tuple[tuple[float, float, float], tuple[float, float, float, float], tuple[float, float, float]]]
"""name -> (top centre xyz, quat wxyz, size: footprint x, y and height above the floor), heading frame."""


class ObjectSource(Protocol):
    def take(self, now_s: float) -> list[tuple[float, Objects]]:
        """Frames that arrived: (stamp on the loop's clock, name -> (xyz, quat wxyz) in the heading frame)."""
        ...

    def close(self) -> None: ...


class PlatformSource(Protocol):
    def take(self, now_s: float) -> list[tuple[float, Platforms]]:
        """Frames that arrived: (stamp on the loop's clock, name -> platform in the heading frame)."""
        ...

    def close(self) -> None: ...


_Frame = TypeVar("_Frame")


class _DdsFrames(Generic[_Frame]):
    """Frames from a DDS perception reader (hardware/ros2/topics.py), stamps moved onto the loop's clock by age."""

    def __init__(self, reader) -> None:
        self.reader = reader

    def take(self, now_s: float) -> list[tuple[float, _Frame]]:
        return [(now_s - r.age_s, self._payload(r)) for r in self.reader.take()]

    @staticmethod
    def _payload(reading) -> _Frame:
        raise NotImplementedError

    def close(self) -> None:
        self.reader.close()


class DdsObjectSource(_DdsFrames[Objects]):
    """ObjectPoses_ from a DDS topic."""

    @staticmethod
    def _payload(reading) -> Objects:
        return reading.objects


class DdsPlatformSource(_DdsFrames[Platforms]):
    """PlatformPoses_ from a DDS topic."""

    @staticmethod
    def _payload(reading) -> Platforms:
        return reading.platforms


@dataclass
class PerceptionCounters:
    frames: int = 0
    platform_frames: int = 0
    rejected: dict[str, int] = field(default_factory=lambda: {"stale": 0, "no_pose": 0, "invalid": 0})
    last_rejection: str = ""


class ObjectPerception:
    """See the module docstring. platform_source: where platforms arrive (None: boxes only)."""

    def __init__(self, config: PerceptionConfig, source: ObjectSource, platform_source: PlatformSource | None = None):
        self.config = config
        self.source = source
        self.platform_source = platform_source
        self.positions: dict[str, np.ndarray] = {}
        """name -> the object's centre in the scene frame (the mean of its recent placements)."""
        self.seen_s: dict[str, float] = {}
        self._frames: dict[str, int] = {}
        """name -> placements in its running mean (at most AVERAGE_FRAMES)."""
        self.platforms: dict[str, Platform] = {}
        """name -> the platform where perception sees it, in the scene frame (the mean of its recent placements)."""
        self._platform_means: dict[str, np.ndarray] = {}
        """name -> (x, y, yaw, size x, size y, height): the running mean behind `platforms`."""
        self.counters = PerceptionCounters()

    def update(self, now_s: float, pose_at: Callable[[float], WorldPose | None]) -> None:
        for stamp, pose, objects in self._placeable(now_s, self.source.take(now_s), pose_at):
            cy, sy = math.cos(pose.yaw_rad), math.sin(pose.yaw_rad)
            for name, (p, _) in objects.items():
                x, y, z = p
                self._place(name, np.array([pose.x_m + cy * x - sy * y, pose.y_m + sy * x + cy * y, pose.z_m + z]))
                self.seen_s[name] = stamp
            self.counters.frames += 1
        if self.platform_source is None:
            return
        for stamp, pose, platforms in self._placeable(now_s, self.platform_source.take(now_s), pose_at):
            cy, sy = math.cos(pose.yaw_rad), math.sin(pose.yaw_rad)
            for name, (p, quat, size) in platforms.items():
                if not np.all(np.isfinite([*p, *quat, *size])):
                    self._invalid(f"platform '{name}': not finite: position {list(p)}, orientation {list(quat)}, "
                                  f"size {list(size)}")
                    continue
                x, y, _ = p
                placed = np.array([pose.x_m + cy * x - sy * y, pose.y_m + sy * x + cy * y,
                                   pose.yaw_rad + yaw_of(np.asarray(quat, dtype=float)), *size], dtype=float)
                if self._place_platform(name, placed):
                    self.seen_s[name] = stamp
            self.counters.platform_frames += 1

    def _placeable(self, now_s: float, frames, pose_at: Callable[[float], WorldPose | None]):
        """(stamp, the robot's estimated pose at it, contents) of the frames that can be placed; stale
        frames and frames without a pose counted and refused by name."""
        c = self.counters
        for stamp, contents in frames:
            age = now_s - stamp
            if age > self.config.max_age_s:
                c.rejected["stale"] += 1
                c.last_rejection = f"stale: {age:.3f} s old (max_age_s {self.config.max_age_s:g})"
                continue
            pose = pose_at(stamp)
            if pose is None:
                c.rejected["no_pose"] += 1
                c.last_rejection = f"no_pose: no estimate of the robot's pose at the stamp ({age:.3f} s ago)"
                continue
            yield stamp, pose, contents

    def _place(self, name: str, placed: np.ndarray) -> None:
        mean = self.positions.get(name)
        if mean is None or float(np.linalg.norm(placed - mean)) > MOVED_M:
            self.positions[name], self._frames[name] = placed, 1
            return
        n = min(self._frames[name] + 1, AVERAGE_FRAMES)
        self.positions[name] = mean + (placed - mean) / n
        self._frames[name] = n

    def _place_platform(self, name: str, placed: np.ndarray) -> bool:
        """Fold one placement (x, y, yaw, size x, size y, height; scene frame) into `name`'s running mean
        (as _place: a jump past MOVED_M starts it over); False, counted as invalid, for a sighting that
        is not a platform the scene could hold."""
        try:
            Platform(name, (placed[0], placed[1]), (placed[3], placed[4]), float(placed[5]), float(placed[2])).validate(
                f"platform '{name}'")
        except LaunchFileError as exc:
            self._invalid(str(exc))
            return False
        mean = self._platform_means.get(name)
        if mean is None or float(np.linalg.norm(placed[:2] - mean[:2])) > MOVED_M:
            mean, self._frames[name] = placed, 1
        else:
            placed[2] = mean[2] + wrap_angle(placed[2] - mean[2])  # the yaw near the mean's, not 2 pi away
            n = min(self._frames[name] + 1, AVERAGE_FRAMES)
            mean = mean + (placed - mean) / n
            self._frames[name] = n
        self._platform_means[name] = mean
        self.platforms[name] = Platform(name, (float(mean[0]), float(mean[1])), (float(mean[3]), float(mean[4])),
                                        float(mean[5]), float(wrap_angle(mean[2])))
        return True

    def _invalid(self, why: str) -> None:
        self.counters.rejected["invalid"] += 1
        self.counters.last_rejection = f"invalid: {why}"

    def close(self) -> None:
        self.source.close()
        if self.platform_source is not None:
            self.platform_source.close()


__all__ = ["DdsObjectSource", "DdsPlatformSource", "ObjectPerception", "ObjectSource", "PerceptionConfig",
           "PerceptionCounters", "PlatformSource"]
