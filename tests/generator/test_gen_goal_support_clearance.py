"""A pick from a table and a place on a higher one, driven kinematically (no physics: the robot is
where the plan says, as in test_gen_goal_executor.py): the planned hands never pass through the
source table's top on their way to the box, and the carried box's bottom never goes into the target
table on the way there (bench objects seed 7, trial 0: a 1.5 kg box from a 0.72 m table to a 0.90 m
one; carried at the pick's height it came into the target table's side on the carry's last steps
and the robot fell in MuJoCo)."""

from __future__ import annotations

import math
import time

import numpy as np

from g1_control.generator.goals.executor import REACHED, GoalConfig, GoalGenerator
from g1_control.generator.goals.stances import TABLE_TOP_THICKNESS_M
from g1_control.scene import Box, SceneConfig, Table
from g1_control.types import PHASE_WHOLE_BODY, Command, TaskGoal
from tests.generator.test_gen_goal_executor import DT, Walking, _state, _tick

TABLE_A = Table("table_a", (1.5474, 0.3731), (0.6, 0.5), 0.7168, -1.3477)
TABLE_B = Table("table_b", (1.1822, -1.3716), (0.7367, 1.0154), 0.8972, -1.7333)
BOX = Box("box", (1.5175, 0.3398), stands_on="table_a", size_m=(0.2821, 0.2112, 0.3844), mass_kg=1.47,
          yaw_rad=-0.7513)
TARGET = (1.2639, -1.2065, 0.8972 + 0.3844 / 2)


def _run() -> tuple[GoalGenerator, list[tuple[float, str, np.ndarray]]]:
    """The pick and the place, driven kinematically; (the generator, (time, goal, reference q) per
    whole-body tick)."""
    inner = Walking()
    gen = GoalGenerator(inner, SceneConfig(tables=[TABLE_A, TABLE_B], boxes=[BOX]), GoalConfig())
    state = _state()
    goals = [TaskGoal("pick", goal_id="pick", object="box"),
             TaskGoal("place", goal_id="place", object="box", target="table_b", pos_w_m=TARGET)]
    seen: list[tuple[float, str, np.ndarray]] = []
    deadline = time.monotonic() + 300.0
    k = 0
    while time.monotonic() < deadline and "place" not in gen.goal_status:
        state.t_s = k * DT
        _tick(gen, inner, state, Command(tasks=goals[:1] if "pick" not in gen.goal_status else goals))
        if gen.phase == PHASE_WHOLE_BODY:
            j = gen.joint_reference(state.t_s)
            w, x, y, z = j.root_quat_wxyz
            seen.append((state.t_s, "place" if "pick" in gen.goal_status else "pick",
                         np.concatenate([j.root_pos_w_m, [x, y, z, w], j.q_rad])))
        k += 1
    return gen, seen


def test_the_hands_and_the_carried_box_stay_clear_of_the_tables_tops():
    gen, seen = _run()
    assert gen.goal_status == {"pick": REACHED, "place": REACHED}, gen.goal_messages
    poses = gen.poses
    held_from = gen.goal_info["pick"]["held_from_s"]
    released = gen.goal_info["place"].get("released_s")
    assert released is not None
    under = BOX.size_m[2] / 2  # the box is held at its centre (a box on a table: stances.hand_height 0)
    hands_in_a, box_in_b, lowest_over_b = 0, 0, math.inf
    t_pick = 0.0
    for t, goal, q in seen:
        hands = [poses.hand_point(q, i) for i in range(2)]
        if goal == "pick":
            t_pick += DT
            # the hands: never inside table_a's top (between its underside and its top surface)
            for p in hands:
                if TABLE_A.contains_xy(p[:2]) and TABLE_A.height_m - TABLE_TOP_THICKNESS_M < p[2] < TABLE_A.height_m:
                    hands_in_a += 1
        elif held_from <= t < released:
            mid = (hands[0] + hands[1]) / 2
            bottom = mid[2] - under
            # the carried box (its footprint's centre and a ring of 0.1 m around it) over table_b
            ring = [mid[:2] + 0.1 * np.array([math.cos(a), math.sin(a)]) for a in np.linspace(0, 2 * math.pi, 8)]
            if any(TABLE_B.contains_xy(p) for p in [mid[:2], *ring]):
                lowest_over_b = min(lowest_over_b, bottom)
                if bottom < TABLE_B.height_m - 0.01:
                    box_in_b += 1
    assert t_pick > 0 and held_from > 0
    assert hands_in_a == 0, f"{hands_in_a} ticks with a hand inside table_a's top"
    assert box_in_b == 0, f"{box_in_b} ticks with the box's bottom below table_b's top over it " \
                          f"(lowest {lowest_over_b:.2f} m, top {TABLE_B.height_m:.2f} m)"
    # and it was set down on table_b (its bottom reached the top there)
    assert lowest_over_b < TABLE_B.height_m + 0.03
