"""A box carried to a table in the tracker's own gait (GoalConfig.walk_while_holding: the whole-body
controller), driven kinematically as in test_gen_goal_carry_over.py (the robot is where the plan says;
walking, the base moves as the goal's walk commands with the arms held at GoalContext.carry_q). To a
0.75 m table the place raises the box first so that its bottom passes over the top with the gait's
lower pelvis (approach.GAIT_PELVIS_DROP_M), walks there holding it (approach.walk_holding: back off,
turn, walk, turn), stands and steps in (handling.walk_in_gait); without the gait the same place walks
in whole-body steps (handling.carry). To a 0.92 m table no raise lifts it clear with the gait's lower
pelvis: the place carries it in whole-body steps, which keep the pelvis higher (nothing raised for the gait
first: the raise is planned and checked before anything moves)."""

from __future__ import annotations

import math
import time
from dataclasses import replace

import numpy as np
import pytest

from g1_control.generator.goals.approach import GAIT_PELVIS_DROP_M
from g1_control.generator.goals.executor import REACHED, GoalConfig, GoalGenerator
from g1_control.generator.goals.handling import BOX_OVER_TOP_M
from g1_control.generator.goals.poses import flat_soles
from g1_control.rotations import yaw_of
from g1_control.scene import Box, SceneConfig, Table
from g1_control.types import PHASE_LOCOMOTION, PHASE_WHOLE_BODY, Command, TaskGoal
from tests.generator.test_gen_goal_carry_over import BOX, TABLE, TARGET
from tests.generator.test_gen_goal_executor import DT, Walking, _state, _tick

TABLE_A = Table("table_a", (0.0, 1.25), (0.8, 0.5), 0.7)
BOX_A = Box("box", (0.0, 1.15), stands_on="table_a", size_m=(0.3, 0.3, 0.3), mass_kg=3.0)
LOW_TABLE = Table("table_b", (1.8, -0.5), (0.5, 0.8), 0.75)
LOW_TARGET = (1.75, -0.5, 0.75 + 0.15)
"""A 3 kg box from a 0.70 m table to a 0.75 m one about 2.5 m away (launch/sim_wbc_carry.yaml's tables, nearer)."""


def _run(config: GoalConfig, scene: SceneConfig | None = None, target=LOW_TARGET
         ) -> tuple[GoalGenerator, dict[str, list[float]], float]:
    """The pick and the place. Per tick while the place holds the box: its bottom (from the hands)
    while walking in the gait ('gait', the pelvis at the gait's height over the soles) and in the
    whole-body plans that carry it ('carry', 'carry in'); and how far the base walked in the gait."""
    inner = Walking()
    scene = scene or SceneConfig(tables=[TABLE_A, LOW_TABLE], boxes=[BOX_A])
    gen = GoalGenerator(inner, scene, config)
    state = _state()
    goals = [TaskGoal("pick", goal_id="pick", object="box"),
             TaskGoal("place", goal_id="place", object="box", target="table_b", pos_w_m=target)]
    seen: dict[str, list[float]] = {}
    walked = 0.0
    deadline = time.monotonic() + 400.0
    k = 0
    ctx = gen.ctx
    while time.monotonic() < deadline and "place" not in gen.goal_status:
        state.t_s = k * DT
        before, yaw = state.base_pos_w_m.copy(), yaw_of(state.imu_quat_wxyz)
        carry_q = ctx.carry_q
        _tick(gen, inner, state, Command(tasks=goals[:1] if "pick" not in gen.goal_status else goals))
        if carry_q is not None and gen.phase == PHASE_LOCOMOTION:  # the goal walks in the gait, arms held
            c = ctx.walk  # the goal's walk moves the base from where it was before the tick (whatever _tick did)
            state.base_pos_w_m = before + DT * np.array([math.cos(yaw) * c[0] - math.sin(yaw) * c[1],
                                                         math.sin(yaw) * c[0] + math.cos(yaw) * c[1], 0.0])
            state.imu_quat_wxyz = np.array([math.cos((yaw + c[2] * DT) / 2), 0, 0, math.sin((yaw + c[2] * DT) / 2)])
            state.base_linvel_w_mps = (state.base_pos_w_m - before) / DT
            state.q_rad = carry_q.copy()
            walked += float(np.hypot(*(state.base_pos_w_m - before)[:2]))
            q = np.concatenate([state.base_pos_w_m, [0.0, 0.0, 0.0, 1.0], carry_q])
            q[3:7] = [0.0, 0.0, state.imu_quat_wxyz[3], state.imu_quat_wxyz[0]]
            held = ctx.held
            assert held is not None
            # the arms held at carry_q over a level pelvis at the gait's height above the floor (z 0)
            hands = np.mean([gen.poses.hand_point(q, i) for i in range(2)], axis=0)
            hands_z = float(hands[2] - q[2]) + gen.poses.nominal_pelvis_m - GAIT_PELVIS_DROP_M
            seen.setdefault("gait", []).append(hands_z - held.hand_dz_m - held.box.size_m[2] / 2)
        plan = ctx.plan
        if gen.phase == PHASE_WHOLE_BODY and ctx.held is not None and "pick" in gen.goal_status and plan is not None \
                and plan.name in ("carry", "carry in"):
            j = gen.joint_reference(state.t_s)
            w, x, y, z = j.root_quat_wxyz
            q = np.concatenate([j.root_pos_w_m, [x, y, z, w], j.q_rad])
            hands = np.mean([gen.poses.hand_point(q, i) for i in range(2)], axis=0)
            seen.setdefault(plan.name, []).append(float(hands[2]) - ctx.held.hand_dz_m - ctx.held.box.size_m[2] / 2)
        k += 1
    return gen, seen, walked


def test_in_the_gait_the_box_is_raised_walked_over_and_set_on_the_table():
    gen, seen, walked = _run(replace(GoalConfig(), walk_while_holding=True))
    assert gen.goal_status == {"pick": REACHED, "place": REACHED}, gen.goal_messages
    assert walked > 0.5 and "carry" not in seen, "walked in the gait, not in whole-body steps"
    assert any("stand holding 'box'" in text for _, text in gen.ctx.log)
    # the gait's lower pelvis counted: the box's bottom over the top by what is asked, within the raise's cm
    for name in ("gait", "carry in"):
        assert name in seen, name
        lowest = min(seen[name])
        assert lowest >= LOW_TABLE.height_m + BOX_OVER_TOP_M - 0.01, \
            f"{name}: the carried box's bottom came to {(lowest - LOW_TABLE.height_m) * 100:.1f} cm over the top"


def test_without_the_gait_the_same_place_carries_in_whole_body_steps():
    gen, seen, walked = _run(GoalConfig())
    assert gen.goal_status == {"pick": REACHED, "place": REACHED}, gen.goal_messages
    assert "carry" in seen and "gait" not in seen and walked == 0.0


def test_a_table_too_high_for_the_gaits_lower_pelvis_is_carried_to_in_whole_body_steps():
    gen, seen, walked = _run(replace(GoalConfig(), walk_while_holding=True), SceneConfig(tables=[TABLE], boxes=[BOX]),
                             TARGET)
    assert gen.goal_status == {"pick": REACHED, "place": REACHED}, gen.goal_messages
    assert "carry" in seen and "gait" not in seen and walked == 0.0
    notes = [text for _, text in gen.ctx.log]
    assert any("in the gait the box's bottom would pass" in text and text.endswith("whole-body steps") for text in notes)
    assert not any("in the gait: the hands" in text for text in notes), "no raise for a gait walk it does not clear"
    assert min(seen["carry"]) >= TABLE.height_m + BOX_OVER_TOP_M - 0.01


def test_the_gaits_hand_height_is_taken_with_the_pelvis_level():
    """gait_hands_m: the pose's arms and waist over a level pelvis at the gait's height (the gait holds the
    pelvis level; a stand may pitch it). Pitched 0.15 rad either way, the same joints give the same walking
    hands as level, where the pose's own hands move by centimetres."""
    from types import SimpleNamespace

    from g1_control.generator.goals.handling import gait_hands_m
    from g1_control.generator.goals.poses import PosePlanner
    from g1_control.robot import g1

    poses = PosePlanner()
    ctx = SimpleNamespace(ik=poses.ik, poses=poses)
    q = poses.ik.nominal()
    for side in ("left", "right"):
        q[7 + g1.JOINT_INDEX[f"{side}_shoulder_pitch_joint"]] = -0.9  # holding something ahead
    level = gait_hands_m(ctx, q)
    hands = min(float(poses.hand_point(q, i)[2]) for i in range(2))
    assert level == pytest.approx(hands - float(q[2]) + poses.nominal_pelvis_m - GAIT_PELVIS_DROP_M, abs=1e-6)
    for pitch in (-0.15, 0.15):
        pitched = q.copy()
        pitched[3:7] = [0.0, math.sin(pitch / 2), 0.0, math.cos(pitch / 2)]
        moved = min(float(poses.hand_point(pitched, i)[2]) for i in range(2)) - hands
        assert abs(moved) > 0.02
        floor = min(float(p[2]) for p, _ in flat_soles(poses.ik, pitched))  # the soles tilt with it
        assert gait_hands_m(ctx, pitched) == pytest.approx(level + floor, abs=1e-6)
