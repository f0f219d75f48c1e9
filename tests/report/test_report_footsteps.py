"""Footsteps vs the plan (report/footsteps.py): touchdowns, steps in the heading frame, pairing, per-style RMS,
each on hand-built cases with known answers; the ankles' forward kinematics against MuJoCo's."""

import math

import mujoco
import numpy as np

from g1_control.report.footsteps import (
    LIFT_M,
    Steps,
    ankle_positions,
    compare_by_style,
    footsteps_by_style,
    pair,
    steps,
    touchdowns,
)
from g1_control.robot import g1
from g1_control.robot.description import mujoco_model


def _walk(n_steps: int, length: float, width: float, yaw: float, period_s: float = 0.4, dt: float = 0.01,
          t0: float = 0.0, lift: float = 0.06):
    """Ankle tracks of a walk along heading `yaw`: feet alternate (left first), each swing lifts `lift`
    and lands `length` ahead of the other foot (a step of `length`, a stride of 2 length), `width` apart."""
    per = round(period_s / dt)
    t = t0 + np.arange((n_steps + 1) * per) * dt
    fwd = np.array([math.cos(yaw), math.sin(yaw)])
    left = np.array([-math.sin(yaw), math.cos(yaw)])
    ankles = np.zeros((len(t), 2, 3))
    pos = [0.5 * width * left, -0.5 * width * left]  # left, right on the ground
    ankles[:, 0, :2], ankles[:, 1, :2] = pos[0], pos[1]
    for k in range(n_steps):
        foot = k % 2
        a, b = k * per, (k + 1) * per
        other = pos[1 - foot]
        side = 0.5 * width * left if foot == 0 else -0.5 * width * left
        target = other + length * fwd + 2 * side
        s = np.linspace(0.0, 1.0, b - a)
        ankles[a:b, foot, :2] = pos[foot] + s[:, None] * (target - pos[foot])
        ankles[a:b, foot, 2] = lift * np.sin(np.pi * s)
        ankles[a:b, 1 - foot, :2] = other
        pos[foot] = target
        ankles[b:, foot, :2] = target
        ankles[b:, 1 - foot, :2] = pos[1 - foot]
    return t, ankles


def test_a_touchdown_is_the_first_tick_back_on_the_ground_after_a_swing():
    z = np.zeros(40)
    z[5:10] = [0.01, 0.03, 0.05, 0.03, 0.005]  # lands at 9
    z[20:24] = [0.01, 0.02, 0.01, 0.0]          # a shuffle under LIFT_M: no step
    z[30:34] = [0.04, 0.06, 0.02, 0.0]          # lands at 33
    assert touchdowns(z, 100).tolist() == [9, 33]
    z[6:9] = LIFT_M - 1e-3  # the first swing never rises LIFT_M
    assert touchdowns(z, 100).tolist() == [33]


def test_steps_are_the_landing_foot_against_the_other_in_the_heading_frame():
    for yaw in (0.0, 1.2, -2.5):
        t, ankles = _walk(6, length=0.3, width=0.2, yaw=yaw)
        s = steps(t, ankles, np.full(len(t), yaw), np.zeros(len(t), dtype=int))
        assert s.foot.tolist() == [0, 1, 0, 1, 0, 1]
        np.testing.assert_allclose(s.step_h_m[:, 0], 0.3, atol=1e-9)
        np.testing.assert_allclose(s.step_h_m[:, 1], [0.2, -0.2] * 3, atol=1e-9)


def test_steps_pair_by_foot_and_time_and_the_rms_is_their_difference():
    t, ankles = _walk(8, length=0.3, width=0.2, yaw=0.4)
    measured = steps(t, ankles, np.full(len(t), 0.4), np.zeros(len(t), dtype=int))
    tp, ap = _walk(8, length=0.25, width=0.2, yaw=0.4, t0=0.1)  # the plan: shorter steps, 0.1 s later
    planned = steps(tp, ap, np.full(len(tp), 0.4), np.zeros(len(tp), dtype=int))
    i, j = pair(measured, planned)
    assert len(i) == 8 and (measured.foot[i] == planned.foot[j]).all()
    np.testing.assert_allclose(planned.t_s[j] - measured.t_s[i], 0.1, atol=1e-9)
    fig = compare_by_style(measured, planned, ["walk"])["walk"]
    assert (fig["steps"], fig["plan_steps"], fig["paired"]) == (8, 8, 8)
    assert math.isclose(fig["rms_x_m"], 0.05, abs_tol=1e-9) and fig["rms_y_m"] < 1e-9
    np.testing.assert_allclose(fig["mean_step_m"], [0.3, 0.2], atol=1e-9)
    np.testing.assert_allclose(fig["plan_mean_step_m"], [0.25, 0.2], atol=1e-9)
    # 0.4 s from the same foot's steps either side (a stride is 0.8 s): nothing pairs.
    late = Steps(planned.t_s + 0.3, planned.foot, planned.step_h_m, planned.style_id)
    assert compare_by_style(measured, late, ["walk"])["walk"]["paired"] == 0


def test_per_style_figures_count_each_style_on_its_own():
    t, ankles = _walk(8, length=0.3, width=0.2, yaw=0.0)
    style = (t >= t[len(t) // 2]).astype(int)
    measured = steps(t, ankles, np.zeros(len(t)), style)
    planned = steps(t, ankles, np.zeros(len(t)), style)
    figs = compare_by_style(measured, planned, ["a", "b"])
    assert figs["a"]["steps"] + figs["b"]["steps"] == 8 and figs["a"]["steps"] > 0 and figs["b"]["steps"] > 0
    assert figs["a"]["rms_m"] == 0.0 and figs["b"]["rms_m"] == 0.0


def test_ankle_kinematics_agree_with_mujoco():
    model = mujoco_model()
    data = mujoco.MjData(model)
    rng = np.random.default_rng(3)
    ids = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, b) for b in g1.FOOT_BODIES]
    rows = []
    for _ in range(5):
        data.qpos[:3] = rng.uniform(-1, 1, 3)
        quat = rng.normal(size=4)
        data.qpos[3:7] = quat / np.linalg.norm(quat)
        data.qpos[7:] = rng.uniform(-0.5, 0.5, model.nq - 7)
        mujoco.mj_kinematics(model, data)
        rows.append((data.qpos[:3].copy(), data.qpos[3:7].copy(), data.qpos[7:].copy(),
                     np.array([data.xpos[i] for i in ids])))
    pos, quat, q, want = (np.array(c) for c in zip(*rows))
    np.testing.assert_allclose(ankle_positions(pos, quat, q), want, atol=1e-6)


def test_a_log_without_a_reference_has_no_footstep_figures():
    n = 10
    log = {"t_s": np.arange(n) * 0.02, "base_pos_m": np.zeros((n, 3)), "base_quat_wxyz": np.tile([1.0, 0, 0, 0], (n, 1)),
           "q_rad": np.zeros((n, g1.NUM_JOINTS)), "q_ref_rad": np.full((n, g1.NUM_JOINTS), np.nan),
           "ref_root_pos_m": np.full((n, 3), np.nan), "ref_root_quat_wxyz": np.full((n, 4), np.nan),
           "style_id": np.zeros(n, dtype=int), "style_names": np.array(["default"])}
    assert footsteps_by_style(log) == {}
