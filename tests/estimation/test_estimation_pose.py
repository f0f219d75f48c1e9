"""LegOdometry (estimation/pose.py): the world pose from the IMU and contact-aided leg kinematics,
anchored at the start, never reading ground truth. Kinematic checks (start frame, heading, a robot
standing still does not drift) and one walk in MuJoCo judged against the simulator's ground truth."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from g1_control.estimation.pose import LegOdometry
from g1_control.robot import g1
from g1_control.types import RobotState


def _quat_z(yaw: float) -> np.ndarray:
    return np.array([math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2)])


@pytest.fixture(scope="module")
def odometry():
    return LegOdometry()


def test_the_start_is_the_origin_heading_zero_and_standing_still_does_not_drift(odometry):
    state = RobotState(q_rad=g1.DEFAULT_Q_RAD.copy(), imu_quat_wxyz=_quat_z(0.5))
    start = odometry.reset(state)
    assert (start.x_m, start.y_m, start.yaw_rad) == (0.0, 0.0, 0.0)
    assert 0.7 < start.z_m < 0.85  # the pelvis over the soles, from the legs
    for k in range(1, 200):
        state.t_s = k * 0.01
        pose = odometry.update(state)
    assert math.hypot(pose.x_m, pose.y_m) < 1e-6 and abs(pose.z_m - start.z_m) < 1e-6
    state.imu_quat_wxyz = _quat_z(0.5 + math.pi / 2)  # turned 90 deg left
    state.t_s += 0.01
    assert odometry.update(state).yaw_rad == pytest.approx(math.pi / 2)


def test_a_planted_foot_holds_the_base_where_the_legs_put_it(odometry):
    """Both feet standing, the pelvis lowered 5 cm by bending the knees: the base moves down by the
    legs' kinematics, not sideways, whatever the (noisy) accelerometer says."""
    q = g1.DEFAULT_Q_RAD.copy()
    state = RobotState(q_rad=q.copy(), imu_acc_mps2=np.array([0.5, -0.3, 9.81]))
    z0 = odometry.reset(state).z_m
    crouch = q.copy()
    for side in ("left", "right"):
        crouch[g1.JOINT_INDEX[f"{side}_hip_pitch_joint"]] -= 0.2
        crouch[g1.JOINT_INDEX[f"{side}_knee_joint"]] += 0.4
        crouch[g1.JOINT_INDEX[f"{side}_ankle_pitch_joint"]] -= 0.2
    for k in range(1, 300):
        state.t_s = k * 0.01
        state.q_rad = q + (crouch - q) * min(1.0, k / 100)
        pose = odometry.update(state)
    assert pose.z_m < z0 - 0.03
    assert math.hypot(pose.x_m, pose.y_m) < 0.02


def test_walking_in_mujoco_the_estimate_stays_close_to_ground_truth():
    from g1_control.launch.builder import build_loop, make_sim_backend
    from g1_control.launch.schema import LaunchFile, Segment
    from g1_control.rotations import yaw_of

    launch = LaunchFile(name="odometry")
    launch.input.timeline = [Segment(1.0, label="stand"), Segment(5.0, vx_mps=0.5, label="forward"),
                             Segment(3.0, wz_radps=0.5, label="turn"), Segment(3.0, vx_mps=0.4, label="forward")]
    launch.output.video = False
    loop = build_loop(launch, backend=make_sim_backend(launch))
    state = loop.reset()
    odometry = LegOdometry()
    odometry.reset(dataclasses.replace(state, base_pos_w_m=None, base_linvel_w_mps=None))
    p0, yaw0 = state.base_pos_w_m[:2].copy(), yaw_of(state.imu_quat_wxyz)
    c, s = math.cos(-yaw0), math.sin(-yaw0)
    every = round(loop.rates.lowlevel_hz / loop.rates.estimator_hz)
    errors, path, last = [], 0.0, np.zeros(2)

    def tick(i: int) -> None:
        nonlocal path, last
        if i % every:
            return
        st = loop.state
        pose = odometry.update(dataclasses.replace(st, base_pos_w_m=None, base_linvel_w_mps=None))
        d = st.base_pos_w_m[:2] - p0
        truth = np.array([c * d[0] - s * d[1], s * d[0] + c * d[1]])
        path += float(np.linalg.norm(truth - last))
        last = truth
        errors.append(math.hypot(pose.x_m - truth[0], pose.y_m - truth[1]))

    loop.run(launch.total_duration_s, progress=tick)
    assert not loop.fell
    print(f"\nleg odometry: {path:.2f} m walked, end error {errors[-1] * 100:.1f} cm, max {max(errors) * 100:.1f} cm")
    assert path > 2.0
    assert errors[-1] < 0.05 * path  # under 5 cm per metre walked


def test_an_accelerometer_spike_at_the_end_of_a_stall_is_not_integrated_over_it():
    """Standing still, the loop stalls 130 ms and the first state after it reads a 40 m/s^2 jolt (a foot's
    impact). Over a gap longer than EstimatorConfig.max_predict_s the velocity is the legs' (zero here),
    not 40 m/s^2 times the gap (5 m/s, 0.08 m of position after the correction); over one 10 ms tick the
    same sample is integrated as always."""
    odometry = LegOdometry()
    state = RobotState(q_rad=g1.DEFAULT_Q_RAD.copy(), imu_acc_mps2=np.array([0.0, 0.0, 9.81]))
    odometry.reset(state)
    for k in range(1, 50):
        state.t_s = k * 0.01
        odometry.update(state)
    jolt = dataclasses.replace(state, t_s=state.t_s + 0.13, imu_acc_mps2=np.array([40.0, 0.0, 9.81]))
    pose = odometry.update(jolt)
    assert abs(odometry.estimator.estimate.base_linvel_w_mps[0]) < 1e-6 and abs(pose.x_m) < 1e-3, pose
    ticked = LegOdometry()
    ticked.reset(state)
    ticked.update(dataclasses.replace(state, t_s=state.t_s + 0.01))
    ticked.update(dataclasses.replace(jolt, t_s=state.t_s + 0.02))
    assert ticked.estimator.estimate.base_linvel_w_mps[0] > 0.3  # 40 m/s^2 over 10 ms, pulled 9 % to zero
