"""A box picked from the floor and carried to a 0.92 m table, driven kinematically (no physics: the
robot is where the plan says, as in test_gen_goal_executor.py). Bench objects seed 19, trial 8: the
standing raise before the carry ended 3 cm short at the arms' reach, the carry's walking pelvis
(SteppingConfig.pelvis_above_ground_m, 0.74 m) took the hands 2 cm lower than the raise's stand and
the hands sagged 1 cm under the tracker: the box's bottom went 0.5-1 cm over the table's top, dragged
on it through the last steps and the robot fell in MuJoCo. The carry is now checked from its plan
(handling.carry): it keeps the raise's pelvis, raises the box further, or refuses."""

from __future__ import annotations

import time
from dataclasses import replace

import numpy as np

from g1_control.generator.goals.executor import REACHED, GoalConfig, GoalGenerator
from g1_control.generator.goals.handling import BOX_OVER_TOP_M, hands_sag_m
from g1_control.robot import g1
from g1_control.scene import Box, SceneConfig, Table
from g1_control.types import PHASE_WHOLE_BODY, Command, TaskGoal
from tests.generator.test_gen_goal_executor import DT, Walking, _state, _tick

TABLE = Table("table_b", (-0.3912, -1.0445), (0.6, 0.5079), 0.9230, 2.0821)
BOX = Box("box", (1.2572, -0.1192), stands_on="floor", size_m=(0.1865, 0.2109, 0.3615), mass_kg=1.22,
          yaw_rad=-1.7985)
TARGET = (-0.3146, -1.0011, 0.9230 + 0.3615 / 2)


def _run(config: GoalConfig) -> tuple[GoalGenerator, list[tuple[str, float]]]:
    """The pick and the place; (the plan's name, the held box's bottom from the planned hands) per
    whole-body tick while the place carries it (before its own set-down)."""
    inner = Walking()
    gen = GoalGenerator(inner, SceneConfig(tables=[TABLE], boxes=[BOX]), config)
    state = _state()
    goals = [TaskGoal("pick", goal_id="pick", object="box"),
             TaskGoal("place", goal_id="place", object="box", target="table_b", pos_w_m=TARGET)]
    seen: list[tuple[str, float]] = []
    deadline = time.monotonic() + 400.0
    k = 0
    while time.monotonic() < deadline and "place" not in gen.goal_status:
        state.t_s = k * DT
        _tick(gen, inner, state, Command(tasks=goals[:1] if "pick" not in gen.goal_status else goals))
        held = gen.ctx.held
        plan = gen.ctx.plan
        if gen.phase == PHASE_WHOLE_BODY and held is not None and "pick" in gen.goal_status and plan is not None \
                and plan.name in ("carry", "correction"):
            j = gen.joint_reference(state.t_s)
            w, x, y, z = j.root_quat_wxyz
            q = np.concatenate([j.root_pos_w_m, [x, y, z, w], j.q_rad])
            hands = np.mean([gen.poses.hand_point(q, i) for i in range(2)], axis=0)
            seen.append((plan.name, float(hands[2]) - held.hand_dz_m - BOX.size_m[2] / 2))
        k += 1
    return gen, seen


def test_the_box_is_carried_to_a_high_table_with_its_bottom_clear_of_the_top():
    gen, seen = _run(GoalConfig())
    assert gen.goal_status == {"pick": REACHED, "place": REACHED}, gen.goal_messages
    assert any(name == "carry" for name, _ in seen)
    lowest = min(bottom for _, bottom in seen)
    # asked: BOX_OVER_TOP_M (8 cm) over the top, within the raise's 1 cm; it was 2.7 cm (the plan alone)
    assert lowest >= TABLE.height_m + BOX_OVER_TOP_M - 0.01, \
        f"the carried box's bottom came to {lowest:.3f} m, {(lowest - TABLE.height_m) * 100:.1f} cm over the top"


def test_without_the_check_the_same_carry_passes_only_centimetres_over_the_top():
    """The baseline the check is for (GoalConfig.carry_over_check off): it shows the test above can fail."""
    _, seen = _run(replace(GoalConfig(), carry_over_check=False))
    assert seen
    lowest = min(bottom for _, bottom in seen)
    assert lowest < TABLE.height_m + 0.04


def test_the_sag_is_how_far_the_measured_hands_sit_below_the_reference():
    """hands_sag_m from the joint angles alone: the elbows bent 0.1 rad further than the reference
    (forearms dropping), the hands sit lower; as planned, none."""
    gen = _run_to_hold()
    ctx = gen.ctx
    assert ctx.state is not None
    assert abs(hands_sag_m(ctx)) < 1e-6
    for side in ("left", "right"):
        ctx.state.q_rad[g1.JOINT_INDEX[f"{side}_shoulder_pitch_joint"]] += 0.1  # the arms swing down
    assert hands_sag_m(ctx) > 0.01


def _run_to_hold() -> GoalGenerator:
    """The pick, driven kinematically until the box is held (the state is the plan's)."""
    inner = Walking()
    gen = GoalGenerator(inner, SceneConfig(tables=[TABLE], boxes=[BOX]), GoalConfig())
    state = _state()
    goals = [TaskGoal("pick", goal_id="pick", object="box")]
    deadline = time.monotonic() + 300.0
    k = 0
    while time.monotonic() < deadline and "pick" not in gen.goal_status:
        state.t_s = k * DT
        _tick(gen, inner, state, Command(tasks=goals))
        k += 1
    assert gen.goal_status.get("pick") == REACHED, gen.goal_messages
    gen.ctx.state = state
    return gen
