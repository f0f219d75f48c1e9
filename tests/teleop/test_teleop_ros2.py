"""input.type ros2: a plain Cyclone DDS peer using ROS 2's names drives the bridge and reads what it publishes.

The peer is what `ros2 topic pub /cmd_vel geometry_msgs/msg/Twist ...` and `ros2 topic echo /odom` are on
the wire: a participant on the same domain with topics `rt/<name>` and types `<pkg>::msg::dds_::<Name>_`."""

from __future__ import annotations

import math
import os
import time
import uuid

import numpy as np
import pytest

from g1_control.errors import LaunchFileError
from g1_control.robot import g1
from g1_control.teleop.ros2 import Ros2Bridge, ros2_settings
from g1_control.types import CommandLimits, EstimatedState, RobotState
from tests.paths import LAUNCH_DIR

DOMAIN = 7


class Peer:
    """A ROS 2 node's view of the topics, without ROS."""

    def __init__(self, partition: str):
        from cyclonedds.pub import DataWriter, Publisher
        from cyclonedds.qos import Policy, Qos
        from cyclonedds.sub import DataReader, Subscriber
        from cyclonedds.topic import Topic

        from g1_control.hardware.links.dds import domain_participant
        from g1_control.hardware.ros2 import messages as m

        dp = domain_participant("lo", DOMAIN)
        group = Qos(Policy.Partition([partition]))
        self.twist = DataWriter(Publisher(dp, qos=group), Topic(dp, "rt/cmd_vel", m.Twist_))
        sub = Subscriber(dp, qos=group)
        keep = Qos(Policy.History.KeepLast(256))  # every sample between two reads, to count the rate
        self.joints = DataReader(sub, Topic(dp, "rt/joint_states", m.JointState_), qos=keep)
        self.odom = DataReader(sub, Topic(dp, "rt/odom", m.Odometry_), qos=keep)
        self.tf = DataReader(sub, Topic(dp, "rt/tf", m.TFMessage_), qos=keep)
        self.m = m

    def send(self, vx, vy, wz):
        m = self.m
        self.twist.write(m.Twist_(m.Vector3_(vx, vy, 0.0), m.Vector3_(0.0, 0.0, wz)))


@pytest.fixture
def pair():
    partition = f"g1ros2-{os.getpid()}-{uuid.uuid4().hex[:8]}"
    bridge = Ros2Bridge("lo", DOMAIN, limits=CommandLimits(vx_mps=(-0.5, 1.0), vy_mps=(-0.4, 0.4),
                                                           wz_radps=(-1.0, 1.0)),
                        stale_after_s=0.5, publish_hz=50.0, partition=partition)
    peer = Peer(partition)
    yield bridge, peer
    bridge.close()


def _poll_until(bridge, now_s, check, timeout_s=3.0):
    end = time.monotonic() + timeout_s
    while time.monotonic() < end:
        command = bridge.poll(now_s)
        if check(command):
            return command
        time.sleep(0.01)
    return bridge.poll(now_s)


def test_a_twist_from_the_peer_becomes_the_command_clipped_to_the_limits(pair):
    bridge, peer = pair
    deadline = time.monotonic() + 3.0
    command = bridge.poll(0.0)
    while command.vx_mps == 0.0 and time.monotonic() < deadline:  # discovery: resend until it arrives
        peer.send(0.6, -0.2, 0.3)
        time.sleep(0.02)
        command = bridge.poll(0.1)
    assert (command.vx_mps, command.vy_mps, command.wz_radps) == (0.6, -0.2, 0.3)
    peer.send(2.0, 1.0, -3.0)
    command = _poll_until(bridge, 0.2, lambda c: c.vx_mps != 0.6)
    assert (command.vx_mps, command.vy_mps, command.wz_radps) == (1.0, 0.4, -1.0)
    # no Twist for longer than stale_after_s: stand
    assert bridge.poll(0.2 + 0.49).vx_mps == 1.0
    stale = bridge.poll(0.2 + 0.51)
    assert (stale.vx_mps, stale.vy_mps, stale.wz_radps) == (0.0, 0.0, 0.0)


def test_a_twist_with_a_nan_is_refused_and_the_robot_stands(pair):
    bridge, peer = pair
    deadline = time.monotonic() + 3.0
    while bridge.poll(0.0).vx_mps == 0.0 and time.monotonic() < deadline:
        peer.send(0.5, 0.0, 0.0)
        time.sleep(0.02)
    peer.send(math.nan, 0.0, 0.0)
    command = _poll_until(bridge, 0.1, lambda c: bridge.refused > 0)
    assert bridge.refused == 1
    assert (command.vx_mps, command.vy_mps, command.wz_radps) == (0.0, 0.0, 0.0)


def test_joint_states_odom_and_tf_reach_the_peer_at_the_publish_rate(pair):
    bridge, peer = pair
    state = RobotState(q_rad=g1.DEFAULT_Q_RAD.copy(), dq_radps=np.full(29, 0.1), tau_nm=np.full(29, 2.0))
    estimate = EstimatedState(base_linvel_w_mps=np.array([0.5, 0.0, 0.0]), heading_velocity=np.array([0.5, 0.0, 0.1]),
                              pelvis_height_m=0.78)
    # 2 s of a 500 Hz loop walking at 0.5 m/s: 100 messages of each kind at 50 Hz
    sent = 0
    for i in range(1000):
        estimate.t_s = i * 0.002
        sent += bridge.publish(estimate.t_s, state, estimate)
    assert sent == 100
    time.sleep(0.3)  # let the last ones arrive; discovery may drop the first few
    deadline = time.monotonic() + 3.0
    joints, odoms, tfs = [], [], []
    while time.monotonic() < deadline and not (joints and odoms and tfs):
        joints += [s for s in peer.joints.take(200) if hasattr(s, "name")]
        odoms += [s for s in peer.odom.take(200) if hasattr(s, "pose")]
        tfs += [s for s in peer.tf.take(200) if hasattr(s, "transforms")]
        time.sleep(0.05)
    assert joints and odoms and tfs
    last = joints[-1]
    assert list(last.name) == list(g1.JOINT_NAMES)
    assert np.allclose(last.position, g1.DEFAULT_Q_RAD) and np.allclose(last.effort, 2.0)
    odom = odoms[-1]
    assert (odom.header.frame_id, odom.child_frame_id) == ("odom", "pelvis")
    # integrated from the estimate: 0.5 m/s for 1.998 s at the last publish (t = 1.98 s)
    assert odom.pose.pose.position.x == pytest.approx(0.5 * 1.98, abs=1e-6)
    assert odom.pose.pose.position.z == pytest.approx(0.78)
    assert odom.twist.twist.linear.x == 0.5
    assert (odom.header.stamp.sec, odom.header.stamp.nanosec) == (1, 980_000_000)
    transform = tfs[-1].transforms[0]
    assert (transform.header.frame_id, transform.child_frame_id) == ("odom", "pelvis")
    assert transform.transform.translation.x == pytest.approx(0.99, abs=1e-6)


@pytest.mark.parametrize(("device", "message"), [
    ({}, "input.device.interface: a ros2 input must name the network interface"),
    ({"interface": "lo", "domain": 300}, "input.device.domain: the ROS_DOMAIN_ID, 0..232; got 300"),
    ({"interface": "lo", "publish_hz": 0}, "input.device.publish_hz: a positive number; got 0"),
    ({"interface": "lo", "stale_after_s": float("nan")}, "input.device.stale_after_s: a positive number; got nan"),
    ({"interface": "lo", "topic": "x"}, "input.device.topic is not a setting of a ros2 input; known: interface,"),
])
def test_bad_settings_are_refused_by_name(device, message):
    with pytest.raises(LaunchFileError) as info:
        ros2_settings(device)
    assert str(info.value).startswith(message)


def test_a_ros2_peer_walks_the_simulated_robot_and_reads_its_odometry(tmp_path):
    """launch/sim_ros2.yaml (MuJoCo, paced to real time): the peer publishes Twist vx 0.4 at 20 Hz from 1.5 s
    on; the robot walks (ground truth) and the peer reads joint_states and odom at about their 50 Hz."""
    import threading

    from g1_control.launch.runner import run
    from g1_control.launch.schema import load_launch

    partition = f"g1ros2-{os.getpid()}-{uuid.uuid4().hex[:8]}"
    launch = load_launch(LAUNCH_DIR / "sim_ros2.yaml", overrides=[
        "duration_s=7", f"input.device.domain={DOMAIN}", f"input.device.partition={partition}", "viewer=false"])
    peer = Peer(partition)
    stop = threading.Event()

    def drive():
        t0 = time.monotonic()
        while not stop.wait(0.05):
            if time.monotonic() - t0 > 1.5:
                peer.send(0.4, 0.0, 0.0)

    joints, odoms = [], []

    def listen():
        while not stop.wait(0.05):
            joints.extend(s for s in peer.joints.take(100) if hasattr(s, "name"))
            odoms.extend(s for s in peer.odom.take(100) if hasattr(s, "pose"))

    threads = [threading.Thread(target=drive, daemon=True), threading.Thread(target=listen, daemon=True)]
    for t in threads:
        t.start()
    try:
        result = run(launch, progress=False)
    finally:
        stop.set()
        for t in threads:
            t.join()
    assert not result.fell
    walking = [s for s in result.segments if s.commanded[0] > 0.3]
    assert walking, [s.commanded for s in result.segments]
    assert walking[-1].achieved[0] > 0.25  # from the simulator's ground truth
    assert len(joints) > 0.5 * 50 * result.duration_s  # ~50 Hz, discovery and load allowing
    assert odoms[-1].pose.pose.position.x > 0.5  # the robot's own dead reckoning saw it walk
    assert odoms[-1].twist.twist.linear.x > 0.2
