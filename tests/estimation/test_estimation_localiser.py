"""Localiser (estimation/localiser.py) over DDS on loopback: a motion-capture PoseStamped published
by the emulator from the simulator's ground truth (g1 sim-robot --mocap: noise, latency, dropouts),
read back (hardware/ros2/topics.py), its latency measured, and fused with the leg odometry of a robot
that stands where the pose says it is not: the estimate moves to the pose; stale poses are refused."""

from __future__ import annotations

import math
import os
import time
import uuid

import numpy as np
import pytest

from g1_control.estimation.external_pose import ExternalPoseConfig, PoseFusion
from g1_control.estimation.localiser import DdsPoseSource, Localiser
from g1_control.estimation.pose import LegOdometry
from g1_control.robot import g1
from g1_control.types import RobotState


def _partition() -> str:
    return f"g1pose-{os.getpid()}-{uuid.uuid4().hex[:8]}"


def _standing(t_s: float, yaw: float = 0.0) -> RobotState:
    return RobotState(t_s=t_s, q_rad=g1.DEFAULT_Q_RAD.copy(),
                      imu_quat_wxyz=np.array([math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2)]))


def test_the_emulators_motion_capture_arrives_late_noisy_and_with_dropouts_as_set():
    from g1_control.hardware.ros2.topics import PoseTopicReader
    from g1_control.sim.emulator import RobotEmulator
    from g1_control.sim.mocap import MocapConfig
    from g1_control.sim.mujoco_backend import MujocoBackend, MujocoConfig

    partition = _partition()
    emulator = RobotEmulator(MujocoBackend(MujocoConfig(lockstep=True)), "lo", 1, partition=partition)
    emulator.publish_mocap(MocapConfig(rate_hz=100.0, noise_m=0.02, latency_s=0.1, dropout=0.3, seed=3), "test/pose")
    reader = PoseTopicReader("lo", 1, "test/pose", partition)
    readings = []
    try:
        emulator.start()  # the built-in controller holds the robot still: ground truth is the start pose
        end = time.monotonic() + 4.0
        while time.monotonic() < end:
            readings += reader.take()
            time.sleep(0.01)
        report = emulator.report()
    finally:
        reader.close()
        emulator.close()
    truth = np.array(report["base_pos_w_m"])
    m = report["mocap"]
    assert len(readings) > 100 and m["sent"] >= len(readings)
    assert 0.2 < m["dropped"] / m["measured"] < 0.4  # 30 % dropouts
    ages = np.array([r.age_s for r in readings])
    # 100 ms late, read within the polling period (10 ms) plus scheduling delays on a shared host
    assert 0.095 < np.median(ages) < 0.2, np.median(ages)
    errors = np.array([[r.x_m, r.y_m, r.z_m] for r in readings]) - truth
    assert 0.012 < errors.std() < 0.03  # 2 cm noise
    assert np.abs(errors.mean(axis=0)).max() < 0.01
    assert {r.frame_id for r in readings} == {"mocap"}


def test_a_standing_robot_is_moved_to_where_the_external_pose_puts_it_and_stale_poses_are_refused():
    """Leg odometry says the robot has not moved from the start; motion capture (frame scene) says it
    stands at (0.2, -0.1), heading 0.1 rad: the fused estimate goes there. Poses 1 s old are refused."""
    from g1_control.hardware.ros2.topics import PoseTopicReader, PoseTopicWriter

    partition = _partition()
    config = ExternalPoseConfig(topic="test/pose", interface="lo", domain=1, partition=partition, frame="scene",
                                max_age_s=0.3, correction_tau_s=0.2)
    writer = PoseTopicWriter("lo", 1, "test/pose", partition)
    localiser = Localiser(LegOdometry(), fusion=PoseFusion(config),
                          source=DdsPoseSource(PoseTopicReader("lo", 1, "test/pose", partition)))
    quat = [math.cos(0.05), 0.0, 0.0, math.sin(0.05)]
    try:
        t0 = time.monotonic()
        localiser.reset(_standing(0.0))
        localiser.update(_standing(0.0))
        end = t0 + 3.0
        while time.monotonic() < end:
            now = time.monotonic()
            writer.write(time.time() - 0.05, [0.2, -0.1, 0.75], quat)  # 50 ms late
            writer.write(time.time() - 1.0, [5.0, 5.0, 0.75], quat)  # stale
            time.sleep(0.01)
            pose = localiser.update(_standing(now - t0))
    finally:
        localiser.close()
        writer.close()
    assert localiser.fusion is not None
    counters = localiser.fusion.counters
    assert counters.accepted > 50 and counters.rejected["stale"] > 50
    assert counters.last_rejection.startswith("stale: 1.0")
    assert (pose.x_m, pose.y_m, pose.yaw_rad) == pytest.approx((0.2, -0.1, 0.1), abs=0.01)
    # the goal executor's view: the state with the estimate as its base pose, its IMU heading (0 when
    # last updated) turned by the estimate's 0.1 rad: an IMU now reading 0.3 rad is 0.4 rad in the scene
    from g1_control.rotations import yaw_of

    scene = localiser.scene_state(_standing(1.0, yaw=0.3))
    assert scene.base_pos_w_m is not None and scene.base_pos_w_m[:2] == pytest.approx([0.2, -0.1], abs=0.01)
    assert yaw_of(scene.imu_quat_wxyz) == pytest.approx(0.4, abs=0.01)
