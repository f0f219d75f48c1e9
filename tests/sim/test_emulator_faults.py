"""The emulator's faults behind the robot-path trip tests (tests/deploy/test_deploy_runtime_trips.py):
"collapse" shows only in the legs' encoders (the estimator's pelvis height), "crc_burst" corrupts
exactly CRC_BURST_STATES states and then the stream is clean."""

from __future__ import annotations

import numpy as np

from g1_control.errors import CrcMismatchError
from g1_control.estimation.estimator import StateEstimator
from g1_control.hardware.links.serial_port import SerialLink
from g1_control.robot import g1
from g1_control.rotations import tilt_rad
from g1_control.safety.fall import FallConfig
from g1_control.sim.emulator import CRC_BURST_STATES, FaultyPhysics
from g1_control.sim.mock_robot import MockG1
from g1_control.sim.robot_endpoint import RobotEndpoint


def test_a_collapse_is_a_low_pelvis_by_leg_kinematics_and_nothing_else():
    physics = FaultyPhysics(MockG1())
    before = physics.reset()
    estimator = StateEstimator()
    assert estimator.update(before).pelvis_height_m > 0.7
    physics.collapsed = True
    state = physics.read_state()
    height = estimator.update(state).pelvis_height_m
    assert height < FallConfig().min_pelvis_height_m - 0.05, height
    assert tilt_rad(state.imu_quat_wxyz) == 0.0, "the IMU stays upright: no tilt trip can stand in for the fall"
    assert np.all(state.q_rad >= g1.Q_MIN_RAD) and np.all(state.q_rad <= g1.Q_MAX_RAD)
    assert np.array_equal(state.dq_radps, before.dq_radps) and np.array_equal(state.q_rad[12:], before.q_rad[12:])


def test_a_crc_burst_corrupts_exactly_its_states_then_the_stream_is_clean():
    link = SerialLink("robot", "loop://")
    sent: list[bytes] = []
    link.send = sent.append  # type: ignore[method-assign]
    endpoint = RobotEndpoint(link, MockG1())
    endpoint.corrupt_next_states = CRC_BURST_STATES
    for _ in range(CRC_BURST_STATES + 5):
        endpoint._publish_state()
    bad = 0
    for i, payload in enumerate(sent):
        try:
            link.decode_state(payload)
        except CrcMismatchError:
            bad += 1
            assert i < CRC_BURST_STATES, f"state {i} is after the burst"
    assert bad == CRC_BURST_STATES and endpoint.corrupt_next_states == 0

