"""`input.type: ros2`: drive the G1 from ROS 2 and see it there, with no ROS installed.

    input:
      type: ros2
      device:
        interface: lo          # the NIC the ROS 2 graph is on (always named; lo: this computer)
        domain: 0              # ROS_DOMAIN_ID
        cmd_vel: cmd_vel       # geometry_msgs/msg/Twist in (linear.x, linear.y, angular.z)
        stale_after_s: 0.5     # no Twist for this long: stand (zero velocity)
        publish_hz: 50         # joint_states, odom and tf out

It subscribes to `geometry_msgs/msg/Twist` on `cmd_vel` (as holosoma and Nav2 publish it) and
publishes `sensor_msgs/msg/JointState` on `joint_states`, `nav_msgs/msg/Odometry` on `odom` and
`tf2_msgs/msg/TFMessage` (odom -> pelvis) on `tf`, under ROS 2's DDS names (`rt/cmd_vel`,
`geometry_msgs::msg::dds_::Twist_`, ...) over the project's Cyclone DDS, so `ros2 topic echo` and
rviz2 on the same domain see them. Odometry is the robot's own estimate (IMU attitude, leg-odometry
velocity integrated from where the run started), never the simulator's ground truth.

A Twist with a non-finite field is refused (counted, named once in the log) and the robot stands;
velocities are clipped to the launch file's limits like any other input.
"""

from __future__ import annotations

import logging
import math
import threading
from collections.abc import Mapping
from typing import Any

import numpy as np

from g1_control.errors import LaunchFileError
from g1_control.interfaces import InputDevice
from g1_control.robot import g1
from g1_control.types import Command, CommandLimits, EstimatedState, ExecutionFeedback, RobotState

log = logging.getLogger(__name__)

DEFAULTS: dict[str, Any] = {"interface": None, "domain": 0, "cmd_vel": "cmd_vel", "stale_after_s": 0.5,
                            "publish_hz": 50.0, "partition": None}
"""input.device keys of a ros2 input and their defaults (interface has none: it is always named)."""
ODOM_FRAME, BASE_FRAME = "odom", "pelvis"


def ros2_settings(device: Mapping[str, Any], where: str = "input.device") -> dict[str, Any]:
    """The device section checked and completed with defaults; LaunchFileError naming the key."""
    unknown = set(device) - set(DEFAULTS) - {"type"}
    if unknown:
        raise LaunchFileError(f"{where}.{sorted(unknown)[0]} is not a setting of a ros2 input; known: "
                              f"{', '.join(DEFAULTS)}")
    out = {**DEFAULTS, **{k: v for k, v in device.items() if k != "type"}}
    if not isinstance(out["interface"], str) or not out["interface"]:
        raise LaunchFileError(f"{where}.interface: a ros2 input must name the network interface of the ROS 2 graph "
                              "('lo' for ROS 2 on this computer)")
    if not isinstance(out["domain"], int) or not 0 <= out["domain"] <= 232:
        raise LaunchFileError(f"{where}.domain: the ROS_DOMAIN_ID, 0..232; got {out['domain']!r}")
    if not isinstance(out["cmd_vel"], str) or not out["cmd_vel"] or out["cmd_vel"].startswith("/rt"):
        raise LaunchFileError(f"{where}.cmd_vel: a ROS 2 topic name such as cmd_vel; got {out['cmd_vel']!r}")
    for key in ("stale_after_s", "publish_hz"):
        value = out[key]
        if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value) or value <= 0:
            raise LaunchFileError(f"{where}.{key}: a positive number; got {value!r}")
    return out


class Ros2Bridge(InputDevice):
    """Twist in, JointState/Odometry/TF out, on ROS 2's DDS names (see the module docstring)."""

    def __init__(self, interface: str, domain: int = 0, *, limits: CommandLimits | None = None,
                 cmd_vel: str = "cmd_vel", stale_after_s: float = 0.5, publish_hz: float = 50.0,
                 partition: str | None = None):
        from cyclonedds.pub import DataWriter, Publisher
        from cyclonedds.qos import Policy, Qos
        from cyclonedds.sub import DataReader, Subscriber
        from cyclonedds.topic import Topic

        from g1_control.hardware.links.dds import DdsEntities, domain_participant
        from g1_control.hardware.ros2 import messages as m

        self.limits, self.stale_after_s, self.period_s = limits, float(stale_after_s), 1.0 / float(publish_hz)
        self._m = m
        # Made, used and deleted under the process-wide DDS entity lock (hardware/links/dds.py: DdsEntities);
        # closed at interpreter exit if nobody closed the bridge.
        self._dds = DdsEntities()
        with self._dds.lock():
            participant = self._dds.add("participant", domain_participant(interface, domain))
            group = Qos(Policy.Partition([partition])) if partition else None
            sub = self._dds.add("subscriber", Subscriber(participant, qos=group))
            pub = self._dds.add("publisher", Publisher(participant, qos=group))
            self._dds.add("twist", DataReader(sub, Topic(participant, m.TOPIC_PREFIX + cmd_vel, m.Twist_)))
            for name, topic, message in (("joints", "joint_states", m.JointState_), ("odom", "odom", m.Odometry_),
                                         ("tf", "tf", m.TFMessage_)):
                self._dds.add(name, DataWriter(pub, Topic(participant, m.TOPIC_PREFIX + topic, message)))
        self._lock = threading.Lock()
        self._velocity = (0.0, 0.0, 0.0)
        self._received_s = -math.inf
        self.refused = 0
        """Twists refused for a non-finite field."""
        self.received = 0
        self._next_publish_s = -math.inf
        self._last_estimate_s: float | None = None
        self._position_w_m = np.zeros(3)
        self._names = list(g1.JOINT_NAMES)

    # -- in -------------------------------------------------------------------------------------------
    def poll(self, now_s: float) -> Command:
        for twist in self._dds.take("twist", 64):  # [] once closed
            if not hasattr(twist, "linear"):
                continue  # a sample-less info (writer gone)
            values = (twist.linear.x, twist.linear.y, twist.angular.z)
            if not all(math.isfinite(v) for v in values):
                self.refused += 1
                if self.refused == 1:
                    log.warning("ros2 input: refused a Twist with a non-finite field %s; standing", values)
                self._velocity, self._received_s = (0.0, 0.0, 0.0), now_s
                continue
            self.received += 1
            self._velocity, self._received_s = values, now_s
        vx, vy, wz = self._velocity if now_s - self._received_s <= self.stale_after_s else (0.0, 0.0, 0.0)
        if self.limits is not None:
            lim = self.limits
            vx = min(max(vx, lim.vx_mps[0]), lim.vx_mps[1])
            vy = min(max(vy, lim.vy_mps[0]), lim.vy_mps[1])
            wz = min(max(wz, lim.wz_radps[0]), lim.wz_radps[1])
        return Command(vx_mps=vx, vy_mps=vy, wz_radps=wz)

    # -- out ------------------------------------------------------------------------------------------
    def observe(self, feedback: ExecutionFeedback) -> None:
        """The loop's record before every poll: publish what the robot reports and its own estimate."""
        if feedback.state is not None:
            self.publish(feedback.t_s, feedback.state, feedback.estimate)

    def describe(self) -> str:
        return "ros2 (Twist on cmd_vel)"

    def publish(self, t_s: float, state: RobotState, estimate: EstimatedState | None) -> bool:
        """Publish joint_states, odom and tf for time `t_s` at most at publish_hz; True when it did."""
        if estimate is not None:
            self._integrate(estimate)
        if t_s < self._next_publish_s - 1e-6:  # a microsecond's slack for the tick clock's rounding
            return False
        self._next_publish_s = t_s + self.period_s
        m = self._m
        stamp = m.stamp(t_s)
        self._dds.write("joints", m.JointState_(m.Header_(stamp, BASE_FRAME), self._names,
                                              [float(v) for v in state.q_rad],
                                              [float(v) for v in state.dq_radps], [float(v) for v in state.tau_nm]))
        quat = estimate.base_quat_wxyz if estimate is not None else state.imu_quat_wxyz
        w, x, y, z = (float(v) for v in quat)
        orientation = m.Quaternion_(x, y, z, w)
        px, py, pz = (float(v) for v in self._position_w_m)
        if estimate is not None:
            vx, vy, _ = (float(v) for v in estimate.heading_velocity)
            wx, wy, wz = (float(v) for v in estimate.base_angvel_b_radps)
        else:
            vx = vy = wx = wy = wz = 0.0
        odom = m.Odometry_(m.Header_(stamp, ODOM_FRAME), BASE_FRAME)
        odom.pose.pose = m.Pose_(m.Point_(px, py, pz), orientation)
        odom.twist.twist = m.Twist_(m.Vector3_(vx, vy, 0.0), m.Vector3_(wx, wy, wz))
        self._dds.write("odom", odom)
        self._dds.write("tf", m.TFMessage_([m.TransformStamped_(m.Header_(stamp, ODOM_FRAME), BASE_FRAME,
                                                                m.Transform_(m.Vector3_(px, py, pz), orientation))]))
        return True

    def _integrate(self, estimate: EstimatedState) -> None:
        """Dead reckoning of the pelvis position in the odom frame from the estimator's world velocity."""
        if self._last_estimate_s is not None:
            dt = estimate.t_s - self._last_estimate_s
            if 0.0 < dt < 0.5:
                self._position_w_m += dt * np.asarray(estimate.base_linvel_w_mps, dtype=float)
        self._last_estimate_s = estimate.t_s
        if estimate.pelvis_height_m is not None:
            self._position_w_m[2] = estimate.pelvis_height_m

    def close(self) -> None:
        """Delete the bridge's entities under the process-wide DDS entity lock (afterwards a poll reads no
        Twist and nothing is published)."""
        self._dds.close()
