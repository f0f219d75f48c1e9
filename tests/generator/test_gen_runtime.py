"""Smart primitives and the runtime generator (with the interpolation in-betweener, so these
tests do not depend on the trained model; test_gen_backbone.py covers the shipped model)."""

import math

import numpy as np
import pytest

from g1_control.generator.baselines import InterpolationInbetweener
from g1_control.generator.primitives import RootState, SpringConfig, spring_root_trajectory
from g1_control.generator.runtime import InbetweeningGenerator
from g1_control.generator.style_stats import StyleStats
from g1_control.interfaces import Generator
from g1_control.robot import g1
from g1_control.types import Command, EffectorGoal, RobotState


def _styles():
    wave = g1.DEFAULT_Q_RAD.copy()
    wave[g1.JOINT_INDEX["right_shoulder_pitch_joint"]] = -1.2
    lift = g1.DEFAULT_Q_RAD.copy()
    return {"default": StyleStats("default", g1.DEFAULT_Q_RAD.copy(), (0.74, 0.76, 0.79)),
            "wave": StyleStats("wave", wave, (0.66, 0.70, 0.73)),
            "lift": StyleStats("lift", lift, (0.55, 0.74, 0.78))}


def _generator():
    gen = InbetweeningGenerator(InterpolationInbetweener(), _styles())
    state = RobotState(q_rad=g1.DEFAULT_Q_RAD.copy(), base_pos_w_m=np.array([0.0, 0.0, 0.76]))
    gen.reset(state)
    return gen, state


def _run(gen, state, command, seconds, t0=0.0, hz=50.0):
    ref = None
    for i in range(int(seconds * hz)):
        state.t_s = t0 + i / hz
        ref = gen.update(command, state)
    return ref


def test_velocity_spring_reaches_the_command_with_the_half_life():
    cfg = SpringConfig(velocity_halflife_s=0.25)
    path, yaw = spring_root_trajectory(RootState(), np.array([0.6, 0.0]), 0.0, None, 2.0, 1 / 30, cfg)
    vel = np.diff(path[:, 0]) * 30  # vel[i]: velocity after i + 2 steps of 1/30 s
    steps = np.arange(2, len(vel) + 2)
    assert np.allclose(vel, 0.6 * (1 - 0.5 ** (steps / 30 / 0.25)), atol=1e-9)  # halves the error per half-life
    assert vel[-1] == pytest.approx(0.6, abs=3e-3) and np.allclose(yaw, 0.0)


def test_heading_spring_is_critically_damped():
    cfg = SpringConfig(heading_halflife_s=0.3)
    _, yaw = spring_root_trajectory(RootState(), np.zeros(2), 0.0, math.pi / 2, 3.0, 1 / 30, cfg)
    assert yaw[-1] == pytest.approx(math.pi / 2, abs=1e-3)
    assert yaw.max() <= math.pi / 2 + 1e-6  # no overshoot
    assert np.all(np.diff(yaw) >= -1e-9)


def test_commands_are_clipped_to_the_configured_speeds():
    cfg = SpringConfig(max_vx_mps=0.5)
    path, _ = spring_root_trajectory(RootState(), np.array([3.0, 0.0]), 0.0, None, 4.0, 1 / 30, cfg)
    assert np.diff(path[:, 0]).max() * 30 <= 0.5 + 1e-9


def test_generator_walks_at_the_commanded_velocity_and_replans_on_change_and_low_buffer():
    gen, state = _generator()
    assert isinstance(gen, Generator)
    ref = _run(gen, state, Command(vx_mps=0.5), 4.0)
    assert ref.root_linvel_h_mps[0] == pytest.approx(0.5, abs=0.05)
    assert gen.stats.replan_reasons["command"] == 1 and gen.stats.replan_reasons["buffer"] >= 5
    x_before = ref.root_pos_w_m[0]
    ref = _run(gen, state, Command(wz_radps=0.6), 3.0, t0=4.0)
    assert gen.stats.replan_reasons["command"] == 2
    assert ref.root_angvel_h_radps[2] == pytest.approx(0.6, abs=0.06)
    assert ref.root_pos_w_m[0] > x_before + 0.1  # coasted ~v * half-life / ln 2 = 0.18 m while stopping


def test_reference_is_continuous_across_replans():
    gen, state = _generator()
    rng = np.random.default_rng(0)
    prev = None
    worst_q, worst_p = 0.0, 0.0
    for i in range(20 * 50):
        if i % 60 == 0:
            cmd = Command(vx_mps=float(rng.uniform(-0.3, 0.8)), wz_radps=float(rng.uniform(-0.8, 0.8)),
                          style=str(rng.choice(["default", "wave"])))
        state.t_s = i / 50
        ref = gen.update(cmd, state)
        if prev is not None:
            worst_q = max(worst_q, np.abs(ref.q_rad - prev[0]).max())
            worst_p = max(worst_p, np.linalg.norm(ref.root_pos_w_m - prev[1]))
        prev = (ref.q_rad.copy(), ref.root_pos_w_m.copy())
    assert worst_q < 0.12  # rad per 20 ms tick: 6 rad/s, well under the motors' limits
    assert worst_p < 0.03  # m per tick: 1.5 m/s


def test_style_pose_is_reached_and_height_follows_command():
    gen, state = _generator()
    ref = _run(gen, state, Command(style="wave"), 3.0)
    j = g1.JOINT_INDEX["right_shoulder_pitch_joint"]
    assert ref.q_rad[j] == pytest.approx(-1.2, abs=0.05) and ref.style == "wave"
    ref = _run(gen, state, Command(pelvis_height_m=0.68), 3.0, t0=3.0)
    assert ref.root_pos_w_m[2] == pytest.approx(0.68, abs=0.01)


def test_unknown_style_falls_back_to_default():
    gen, state = _generator()
    ref = _run(gen, state, Command(style="moonwalk"), 1.0)
    assert ref.style == "default"


def test_box_goal_walks_to_the_box_then_crouches_with_hands_on_it():
    gen, state = _generator()
    box = np.array([2.0, 1.0, 0.25])
    cmd = Command(goals=[EffectorGoal("box_pick", box)])
    ref = _run(gen, state, cmd, 12.0)
    dist = np.linalg.norm(ref.root_pos_w_m[:2] - box[:2])
    assert dist == pytest.approx(0.45, abs=0.2)
    assert ref.root_pos_w_m[2] < 0.6 and ref.style == "lift"
    assert set(ref.frame_targets_w) == set(g1.HAND_BODIES)
    assert np.linalg.norm(ref.frame_targets_w["left_wrist_yaw_link"][:3] - box) == pytest.approx(0.2)


def test_climb_goal_ends_standing_on_the_box():
    gen, state = _generator()
    box = np.array([1.5, 0.0, 0.15])
    ref = _run(gen, state, Command(goals=[EffectorGoal("box_climb", box)]), 10.0)
    assert np.linalg.norm(ref.root_pos_w_m[:2] - box[:2]) < 0.1
    assert ref.root_pos_w_m[2] == pytest.approx(0.30 + 0.76, abs=0.02) and ref.style == "climb"


def test_effector_goal_becomes_a_frame_target():
    gen, state = _generator()
    goal = np.array([0.4, -0.2, 1.0])
    ref = _run(gen, state, Command(goals=[EffectorGoal("right_wrist_yaw_link", goal)]), 0.5)
    assert np.allclose(ref.frame_targets_w["right_wrist_yaw_link"][:3], goal)


def test_long_rollout_under_random_commands_stays_healthy():
    from g1_control.tools.bench_generator import long_rollout

    gen = InbetweeningGenerator(InterpolationInbetweener(), _styles())
    result = long_rollout(gen, seconds=60.0)
    assert result["finite"] and result["joint_limit_violations"] == 0
    assert 0.5 < result["pelvis_min_m"] and result["pelvis_max_m"] < 0.9
    assert result["replans"] > 60 and result["fallbacks"] == 0
    assert result["leg_speed_last_min_radps"] > 0.0


def test_effector_goals_are_reached_through_the_ik():
    from g1_control.tools.bench_generator import effector_goals_through_ik

    result = effector_goals_through_ik(lambda: InbetweeningGenerator(InterpolationInbetweener(), _styles()), goals=4)
    assert result["success"] == 1.0 and result["mean_m"] < 0.05


def _plan_velocity(gen, command, seconds=8.0, settle_s=3.0, hz=50.0):
    """The plan's root velocity, open loop (no physics), heading frame halfway through the window."""
    from g1_control.rotations import yaw_of

    state = RobotState(q_rad=g1.DEFAULT_Q_RAD.copy(), base_pos_w_m=np.array([0.0, 0.0, 0.76]))
    track = []
    for i in range(int(seconds * hz)):
        state.t_s = i / hz
        ref = gen.update(command, state)
        track.append((state.t_s, *ref.root_pos_w_m[:2], yaw_of(ref.root_quat_wxyz)))
    t, x, y, yaw = np.array(track).T
    yaw = np.unwrap(yaw)
    a, b = np.searchsorted(t, settle_s), len(t) - 1
    mid = 0.5 * (yaw[a] + yaw[b])
    d = np.array([x[b] - x[a], y[b] - y[a]]) / (t[b] - t[a])
    return (math.cos(mid) * d[0] + math.sin(mid) * d[1], -math.sin(mid) * d[0] + math.cos(mid) * d[1],
            (yaw[b] - yaw[a]) / (t[b] - t[a]))


@pytest.mark.parametrize("command", [Command(0.0, 0.25, 0.0, style="carry"), Command(0.6, 0.0, 0.0, style="wave"),
                                     Command(-0.3, 0.0, 0.0, style="guard"), Command(0.5, 0.0, 0.0)])
def test_the_shipped_backbone_plans_the_commanded_velocity(command):
    """Open loop, the in-betweener alone planned 0.30-0.37 m/s sideways for 0.25 and drifted 0.06-0.20 m/s
    sideways and 0.03-0.13 rad/s walking forward (five styles); walking straight, the plan-velocity feedback
    (RuntimeConfig.velocity_feedback_gain) holds the plan to the command: a tracker that walks the plan
    (the whole-body controller) walks these errors."""
    from g1_control.launch.builder import make_generator
    from g1_control.launch.schema import load_launch
    from tests.paths import LAUNCH_DIR

    gen = make_generator(load_launch(LAUNCH_DIR / "sim_generator.yaml"))
    vx, vy, wz = _plan_velocity(gen, command)
    want = (command.vx_mps, command.vy_mps, command.wz_radps)
    for got, c in zip((vx, vy, wz), want):
        assert abs(got - c) <= max(0.1 * abs(c), 0.05), f"planned {vx:+.2f} {vy:+.2f} {wz:+.2f} for {want}"
