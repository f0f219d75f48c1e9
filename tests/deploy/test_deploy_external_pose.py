"""The robot path steering by leg odometry fused with motion capture (issue 24): `g1 sim-robot --mocap`
(a PoseStamped from the simulator's ground truth with 2 cm / 3 deg noise, 100 ms latency, 10 %
dropouts) and `g1 deploy launch/sim2sim_mocap.yaml --yes` (walk, turn, walk) as two processes. The
deploy reports how many poses it accepted and refused; its last pose is judged against the emulator's
ground truth when damping arrived."""

from __future__ import annotations

import json
import math

import pytest
from deploy_test_helpers import deploy_to_the_end

from tests.paths import LAUNCH_DIR

pytestmark = pytest.mark.timing

MOCAP = ("--mocap", "--mocap-noise-m", "0.02", "--mocap-noise-deg", "3", "--mocap-latency-s", "0.1",
         "--mocap-dropout", "0.1", "--mocap-seed", "7")


def test_the_fused_estimate_ends_where_the_simulator_says_the_robot_is(tmp_path, partition):
    report_path = tmp_path / "deploy.json"
    host, wire = deploy_to_the_end(partition, LAUNCH_DIR / "sim2sim_mocap.yaml", report_path, tmp_path,
                                   emulator_flags=("--lower-gantry-on-policy", *MOCAP))
    report = json.loads(report_path.read_text())
    loc = report["localisation"]
    assert loc["source"] == "leg odometry fused with an external pose"
    ext = loc["external_pose"]
    console = "\n".join(host.seen)
    assert f"external poses: {ext['accepted']} accepted, refused: " in console
    mocap = wire["mocap"]
    assert 0.05 < mocap["dropped"] / mocap["measured"] < 0.15  # 10 % dropouts
    assert ext["accepted"] > 500 and ext["rejected"]["jump"] == 0
    truth, pose = wire["first_damping_base_pos_w_m"], loc["pose_at_damping"]
    lowered = wire["gantry_lowered_base_pos_w_m"]
    walked = math.hypot(truth[0] - lowered[0], truth[1] - lowered[1])
    error = math.hypot(pose["x_m"] - truth[0], pose["y_m"] - truth[1])
    print(f"\nsim2sim with motion capture: {walked:.2f} m from where it was lowered, fused estimate "
          f"{error * 100:.1f} cm from ground truth at damping; external poses {ext}; emulator mocap {mocap}")
    assert walked > 1.5
    assert error < 0.06
