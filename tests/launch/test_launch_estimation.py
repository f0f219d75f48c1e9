"""launch file `estimation`: what goals and programs steer by. MuJoCo keeps ground truth by default
(no localiser is built: the loop runs as before); `steer_by: estimate` makes the goal executor place a
world-point reach by the robot's own leg odometry, anchored where it started, and the reach is judged
from the simulator's ground truth."""

from __future__ import annotations

import numpy as np

from g1_control.launch.builder import build_loop, make_sim_backend
from g1_control.launch.schema import parse_launch
from g1_control.report.outcomes import GoalWatcher


def _reach_launch(steer_by: str):
    return parse_launch({
        "name": "reach-by-estimate", "rates": {"tracker_hz": 100}, "tracker": {"type": "layer"},
        "estimation": {"steer_by": steer_by}, "output": {"video": False}, "viewer": False,
        "input": {"type": "scripted", "timeline": [
            {"duration_s": 2, "label": "stand"},
            {"duration_s": 5, "label": "right ahead",
             "goals": [{"kind": "reach", "hand": "right", "pos_w_m": [0.40, -0.20, 0.95]}]}]}})


def test_mujoco_steers_by_ground_truth_unless_told_and_builds_no_localiser():
    launch = _reach_launch("auto")
    loop = build_loop(launch, backend=make_sim_backend(launch))
    assert loop.localiser is None and "localiser" not in loop.chain
    assert loop.generator.estimate is None  # the goal executor sees the state as the simulator reports it


def test_a_world_point_reach_placed_by_the_estimate_is_judged_from_ground_truth():
    launch = _reach_launch("estimate")
    loop = build_loop(launch, backend=make_sim_backend(launch))
    assert loop.localiser is not None and loop.chain["localiser"] == "leg odometry"
    watcher = GoalWatcher(loop)
    loop.reset()
    seen = []

    def tick(i: int) -> None:
        watcher.tick(i)
        ctx = loop.generator.ctx
        if i % 50 == 0 and ctx.state is not None and ctx.state.base_pos_w_m is not None:
            seen.append((ctx.state.base_pos_w_m.copy(), loop.state.base_pos_w_m.copy(), loop.localiser.pose))

    loop.run(launch.total_duration_s, progress=tick)
    assert not loop.fell
    [outcome] = watcher.outcomes()
    print(f"\nreach placed by leg odometry: {outcome}")
    assert outcome["status"] == "reached", outcome
    assert outcome["hand_error_max_m"] < 0.03  # ground truth: the hand at the world point
    # the executor's world pose was the estimate, not the simulator's (which differs from it)
    used, truth, pose = seen[-1]
    assert np.allclose(used, [pose.x_m, pose.y_m, pose.z_m])
    assert not np.allclose(used, truth, atol=1e-6)
    assert loop.feedback.pose is not None and abs(loop.feedback.pose.t_s - loop.localiser.pose.t_s) < 0.05  # to the input
