"""`g1 bench objects` picks planned as handling.pick plans them, without physics: the drawn scene's
stance (stances.StancePlanner.plan), the pose the robot steps in with, and the via and pre-grasp poses."""

import math

import numpy as np

from g1_control.generator.goals.box import hand_points
from g1_control.generator.goals.context import GoalConfig
from g1_control.generator.goals.handling import RAISE_AHEAD_M
from g1_control.generator.goals.stances import ARMS_BACK, grasp_hold_poses, pick_headings
from g1_control.tools.bench_objects import draw_scene


def planned_pick(stances, seed, index):
    """(plan, table, center, stand): the trial's pick stance, its support, the box's centre and the pose
    the robot steps in with (upright at the stance, the arms swung back)."""
    drawn = draw_scene(seed, index)
    box = drawn["scene"].boxes[0]
    table = drawn["scene"].block(box.stands_on)
    center = np.array([*box.xy_m, table.height_m + box.size_m[2] / 2])
    plan = stances.plan(box, center, table, pick_headings(box, center[:2], table, np.zeros(2)),
                        lift_m=GoalConfig().lift_m, what="pick it up")
    stand, _ = stances.stance(plan.approach.mid_xy, plan.approach.heading, 0.0)
    stand[7:] = ARMS_BACK
    return plan, table, center, stand


def via_and_pre(stances, seed, index):
    """(plan, table, soles, q_via, q_pre): the pick's stance and its via and pre-grasp poses."""
    plan, table, center, stand = planned_pick(stances, seed, index)
    _, soles = stances.stance(plan.approach.mid_xy, plan.approach.heading, 0.0)
    heading, width = plan.approach.heading, plan.width_m
    c = center + np.array([0.0, 0.0, plan.hand_dz_m])
    ahead = float((c[:2] - plan.approach.mid_xy) @ np.array([math.cos(heading), math.sin(heading)]))
    gap = GoalConfig().pre_gap_m
    via = hand_points(c, heading, width, gap + 0.03, dz_m=0.08, ahead_m=-(ahead - RAISE_AHEAD_M))
    pre = hand_points(c, heading, width, gap)
    steps = [("via", via, np.zeros(2), plan.pelvis_z_m, plan.lean),
             ("pre-grasp", pre, np.zeros(2), plan.pelvis_z_m, plan.lean)]
    q_via, q_pre = grasp_hold_poses(stances.poses, stand, soles, heading, steps, "box", "test")
    return plan, table, soles, q_via, q_pre
