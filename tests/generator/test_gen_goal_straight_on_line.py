"""From a stance on the box's line the hands go from their via pose to the pre-grasp pose along the
joint-space blend, and straight (stances.straight_poses, given the support) only where that blend
takes a hand into the support's top: `g1 bench objects` 144.0 (a 0.3 kg box on a 0.85 m table) fell
at the pick on main, its right hand rising into the top's underside along the blend (traced: the
plan's hand inside the outline, 1 cm under the top). The straight poses are timed by joint speed
(handling._timed), not spread over a second (a wrist turned at 24.8 rad/s on 143.10 so)."""

from itertools import pairwise

import numpy as np
import pytest

from g1_control.generator.goals.handling import JOINT_SPEED_RADPS, _timed
from g1_control.generator.goals.poses import PosePlanner
from g1_control.generator.goals.stances import StancePlanner, path_meets, straight_poses
from tests.generator.bench_picks import via_and_pre


@pytest.fixture(scope="module")
def stances():
    return StancePlanner(PosePlanner())


def test_on_the_line_the_hands_go_straight_where_the_blend_meets_the_top(stances):
    plan, table, soles, q_via, q_pre = via_and_pre(stances, 144, 0)
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
    plan, table, soles, q_via, q_pre = via_and_pre(stances, 147, 2)
    heading, poses = plan.approach.heading, stances.poses
    assert not path_meets(poses, q_via, q_pre, heading, table)
    assert straight_poses(poses, q_via, q_pre, soles, heading, np.zeros(2), plan.pelvis_z_m, plan.lean, table) == []
    # without the support the straight poses are always made (a stance off the line)
    assert straight_poses(poses, q_via, q_pre, soles, heading, np.zeros(2), plan.pelvis_z_m, plan.lean)
