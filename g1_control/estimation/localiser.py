"""Localiser: the robot's world pose in the launch file's scene frame, from what a robot has.

Leg odometry (pose.py: IMU + contact-aided leg kinematics, anchored where the run starts) placed at
the robot's start pose in the scene (the origin, facing +x, unless told otherwise), and, where an
external pose input is configured (launch file `estimation.external_pose`), fused with that pose
(external_pose.py: latency compensated, stale or jumping poses refused by name).

The loop updates it after its state estimator each estimator tick (it shares the estimator's
kinematics) and reports `pose` in its feedback (ExecutionFeedback.pose); the goal executor and the
program runner steer by it where there is no ground truth (on the robot), or when told to
(`estimation.steer_by: estimate` in simulation). Nothing here reads ground truth.

    localiser = Localiser(LegOdometry(loop.estimator, shared=True), fusion=PoseFusion(config),
                          source=DdsPoseSource(reader))
    localiser.update(state)        # after loop.estimator.update(state)
    localiser.pose                 # WorldPose in the scene frame
    localiser.scene_state(state)   # the state with the estimate as its base pose (for the goal executor)
"""

from __future__ import annotations

import dataclasses
import math
from collections import deque
from typing import Protocol

import numpy as np

from g1_control.estimation.external_pose import Planar, PoseFusion, PoseSample
from g1_control.estimation.perception import ObjectPerception
from g1_control.estimation.pose import LegOdometry
from g1_control.rotations import wrap_angle, yaw_of
from g1_control.scene import Platform
from g1_control.types import RobotState, WorldPose

TRACK_PERIOD_S = 0.05
TRACK_LENGTH = 72_000


class PoseSource(Protocol):
    """Where external poses come from: take(now_s) -> the poses that arrived, stamped on the loop's clock."""

    def take(self, now_s: float) -> list[PoseSample]: ...

    def close(self) -> None: ...


class DdsPoseSource:
    """PoseStamped from a DDS topic (hardware/ros2/topics.py), stamps moved onto the loop's clock by
    their age (the publisher's wall clock against this host's)."""

    def __init__(self, reader) -> None:
        self.reader = reader

    def take(self, now_s: float) -> list[PoseSample]:
        return [PoseSample(now_s - r.age_s, r.x_m, r.y_m, r.yaw_rad) for r in self.reader.take()]

    def close(self) -> None:
        self.reader.close()


class Localiser:
    """See the module docstring. start: the robot's start pose in the scene (x_m, y_m, yaw_rad)."""

    def __init__(self, odometry: LegOdometry, start: tuple[float, float, float] = (0.0, 0.0, 0.0),
                 fusion: PoseFusion | None = None, source: PoseSource | None = None,
                 objects: ObjectPerception | None = None):
        if source is not None and fusion is None:
            raise ValueError("Localiser: an external pose source needs a PoseFusion to fuse it")
        self.odometry = odometry
        self.start = Planar(0.0, *start)
        self.fusion = fusion
        self.source = source
        self.objects = objects
        """Perception of named objects, placed in the scene with this estimate (estimation/perception.py)."""
        self.pose: WorldPose | None = None
        self.track: deque[WorldPose] = deque(maxlen=TRACK_LENGTH)
        """The pose every TRACK_PERIOD_S (the last hour): where the estimate was when (reports, perception)."""
        self._yaw_offset = 0.0

    def reset(self, state: RobotState) -> None:
        self.odometry.restart()
        self.pose = None
        self.track.clear()
        if self.fusion is not None:
            self.fusion = PoseFusion(self.fusion.config)

    def update(self, state: RobotState) -> WorldPose:
        odo = self.odometry.update(state)
        x, y, yaw = self.start.compose(odo.x_m, odo.y_m, odo.yaw_rad)
        if self.fusion is not None:
            self.fusion.update(Planar(odo.t_s, x, y, yaw))
            if self.source is not None:
                for sample in self.source.take(state.t_s):
                    self.fusion.measure(sample)
            fused = self.fusion.fused
            assert fused is not None  # set by update()
            x, y, yaw = fused.x_m, fused.y_m, fused.yaw_rad
        self.pose = WorldPose(odo.t_s, x, y, odo.z_m, yaw)
        if not self.track or odo.t_s >= self.track[-1].t_s + TRACK_PERIOD_S:
            self.track.append(self.pose)
        if self.objects is not None:
            self.objects.update(state.t_s, self.pose_at)
        self._yaw_offset = wrap_angle(yaw - yaw_of(state.imu_quat_wxyz))
        return self.pose

    def pose_at(self, t_s: float) -> WorldPose | None:
        """The estimate at `t_s` (the loop's clock): linear between tracked poses, the current pose after
        the last; None before the track or after now."""
        pose, track = self.pose, self.track
        if pose is None or not track or t_s < track[0].t_s or t_s > pose.t_s + 1e-9:
            return None
        later = pose
        for earlier in reversed(track):  # recent stamps: a few steps from the end
            if earlier.t_s <= t_s:
                span = later.t_s - earlier.t_s
                f = 0.0 if span <= 0 else (t_s - earlier.t_s) / span
                return WorldPose(t_s, earlier.x_m + f * (later.x_m - earlier.x_m),
                                 earlier.y_m + f * (later.y_m - earlier.y_m), earlier.z_m + f * (later.z_m - earlier.z_m),
                                 float(wrap_angle(earlier.yaw_rad + f * wrap_angle(later.yaw_rad - earlier.yaw_rad))))
            later = earlier
        return None

    def object_positions(self) -> dict[str, np.ndarray]:
        """Objects seen by perception (estimation/perception.py), in the scene frame; {} without one."""
        return self.objects.positions if self.objects is not None else {}

    def platforms_seen(self) -> dict[str, Platform]:
        """Platforms seen by perception (estimation/perception.py), in the scene frame; {} without one."""
        return self.objects.platforms if self.objects is not None else {}

    def scene_state(self, state: RobotState) -> RobotState:
        """`state` with this estimate as its base pose in the scene frame: base_pos_w_m, the IMU's
        orientation turned to the estimated heading, and the estimator's velocity in scene axes."""
        pose = self.pose
        if pose is None:
            return state
        c, s = math.cos(self._yaw_offset / 2), math.sin(self._yaw_offset / 2)
        w, x, y, z = state.imu_quat_wxyz.tolist()
        quat = np.array([c * w - s * z, c * x - s * y, c * y + s * x, c * z + s * w])  # rot_z(offset) * q
        vel = self.odometry.estimator.estimate.base_linvel_w_mps
        co, so = math.cos(self._yaw_offset), math.sin(self._yaw_offset)
        vel_scene = np.array([co * vel[0] - so * vel[1], so * vel[0] + co * vel[1], vel[2]])
        return dataclasses.replace(state, base_pos_w_m=np.array([pose.x_m, pose.y_m, pose.z_m]),
                                   imu_quat_wxyz=quat, base_linvel_w_mps=vel_scene)

    def describe(self) -> str:
        what = "leg odometry"
        if self.fusion is not None:
            what += " fused with an external pose"
        if self.objects is not None:
            what += ", objects from perception"
        if self.fusion is not None:
            what += "; " + self.fusion.describe()
        return what

    def close(self) -> None:
        if self.source is not None:
            self.source.close()
        if self.objects is not None:
            self.objects.close()


__all__ = ["DdsPoseSource", "Localiser", "PoseSource"]
