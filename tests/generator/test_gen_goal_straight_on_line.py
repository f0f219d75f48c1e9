"""From a stance on the box's line the hands go from their via pose to the pre-grasp pose along the
joint-space blend, and straight (stances.straight_poses, given the support) only where that blend
takes a hand into the support's top: `g1 bench objects` 144.0 (a 0.3 kg box on a 0.85 m table) fell
at the pick on main, its right hand rising into the top's underside along the blend (traced: the
plan's hand inside the outline, 1 cm under the top). The straight poses are timed by joint speed
(handling._timed), not spread over a second (a wrist turned at 24.8 rad/s on 143.10 so)."""

import math
from itertools import pairwise

import numpy as np
import pytest

from g1_control.generator.goals.box import hand_points
from g1_control.generator.goals.context import GoalConfig
from g1_control.generator.goals.handling import ARMS_BACK, JOINT_SPEED_RADPS, RAISE_AHEAD_M, _timed
from g1_control.generator.goals.poses import PosePlanner
from g1_control.generator.goals.stances import (
    StancePlanner,
    grasp_hold_poses,
    path_meets,
    pick_headings,
    straight_poses,
)
from g1_control.tools.bench_objects import draw_scene


@pytest.fixture(scope="module")
def stances():
    return StancePlanner(PosePlanner())


def _via_and_pre(stances, seed, index):
    """The scene's pick planned as handling.pick plans it: its stance, via and pre-grasp poses."""
    drawn = draw_scene(seed, index)
    box = drawn["scene"].boxes[0]
    table = drawn["scene"].block(box.stands_on)
    center = np.array([*box.xy_m, table.height_m + box.size_m[2] / 2])
    plan = stances.plan(box, center, table, pick_headings(box, center[:2], table, np.zeros(2)),
                        lift_m=GoalConfig().lift_m, what="pick it up")
    q0, soles = stances.stance(plan.approach.mid_xy, plan.approach.heading, 0.0)
    q0[7:] = ARMS_BACK  # as handling.pick steps in
    heading, width = plan.approach.heading, plan.width_m
    c = center + np.array([0.0, 0.0, plan.hand_dz_m])
    ahead = float((c[:2] - plan.approach.mid_xy) @ np.array([math.cos(heading), math.sin(heading)]))
    gap = GoalConfig().pre_gap_m
    via = hand_points(c, heading, width, gap + 0.03, dz_m=0.08, ahead_m=-(ahead - RAISE_AHEAD_M))
    pre = hand_points(c, heading, width, gap)
    steps = [("via", via, np.zeros(2), plan.pelvis_z_m, plan.lean),
             ("pre-grasp", pre, np.zeros(2), plan.pelvis_z_m, plan.lean)]
    q_via, q_pre = grasp_hold_poses(stances.poses, q0, soles, heading, steps, box.name, "test")
    return plan, table, soles, q_via, q_pre


def test_on_the_line_the_hands_go_straight_where_the_blend_meets_the_top(stances):
    plan, table, soles, q_via, q_pre = _via_and_pre(stances, 144, 0)
    assert plan.chosen.side_m == 0.0
    heading, poses = plan.approach.heading, stances.poses
    assert path_meets(poses, q_via, q_pre, heading, table)
    straight = straight_poses(poses, q_via, q_pre, soles, heading, np.zeros(2), plan.pelvis_z_m, plan.lean, table)
    assert straight
    chain = [q_via, *straight, q_pre]
    assert not any(path_meets(poses, u, v, heading, table) for u, v in pairwise(chain))
    # timed by joint speed: no joint faster than JOINT_SPEED_RADPS on average between two poses
    timed = _timed(q_via, [*straight, q_pre], 1.0)
    times = [0.0] + [t for t, _ in timed]
    for (t0, t1), (u, v) in zip(pairwise(times), pairwise(chain), strict=True):
        assert float(np.abs(v[7:] - u[7:]).max()) / (t1 - t0) <= JOINT_SPEED_RADPS + 1e-9


def test_on_the_line_a_clear_blend_is_kept(stances):
    # bench objects 147.2: a 2.2 kg box from a 0.69 m table, the blend over its top (placed on main)
    plan, table, soles, q_via, q_pre = _via_and_pre(stances, 147, 2)
    heading, poses = plan.approach.heading, stances.poses
    assert not path_meets(poses, q_via, q_pre, heading, table)
    assert straight_poses(poses, q_via, q_pre, soles, heading, np.zeros(2), plan.pelvis_z_m, plan.lean, table) == []
    # without the support the straight poses are always made (a stance off the line)
    assert straight_poses(poses, q_via, q_pre, soles, heading, np.zeros(2), plan.pelvis_z_m, plan.lean)
