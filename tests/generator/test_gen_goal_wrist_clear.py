"""The wrists keep clear of a support's top on the hands' way to a box (stances.WRIST_CLEAR_M):
`g1 bench objects` 145.1 (a 5.1 kg box on a 0.89 m table) fell at the pick on main, the left wrist
rising into the top's underside while the hand points, their tips and the elbows kept their 2 cm (traced: the wrist
joint 2.6 cm outside the edge, 1.2 cm under the top, along the blend from the stance to the via pose)."""

from itertools import pairwise

import numpy as np
import pytest

from g1_control.generator.goals import stances as stances_module
from g1_control.generator.goals.poses import PosePlanner
from g1_control.generator.goals.stances import (
    CLEAR_MARGIN_M,
    TABLE_TOP_THICKNESS_M,
    WRIST_CLEAR_M,
    WRISTS,
    StancePlanner,
    detour_poses,
    path_meets,
)
from tests.generator.bench_picks import planned_pick, via_and_pre


@pytest.fixture(scope="module")
def stances():
    return StancePlanner(PosePlanner())


def _wrist_under(poses, chain, table):
    """The nearest a wrist joint comes to the table's outline while within WRIST_CLEAR_M of its top's
    slab (inf: never there), along the joint-space blends of `chain`."""
    near = np.inf
    underside = table.height_m - TABLE_TOP_THICKNESS_M
    for u, v in pairwise(chain):
        for s in np.linspace(0.0, 1.0, 25):
            q = u + s * (v - u)
            q[3:7] /= np.linalg.norm(q[3:7])
            for f in WRISTS:
                p = poses.ik.frame_pose(q, f)[0]
                if underside - WRIST_CLEAR_M < p[2] < table.height_m:
                    near = min(near, table.distance_xy(p[:2]))
    return near


def test_the_wrists_go_around_a_high_tops_edge_where_the_hands_alone_would_pass(stances, monkeypatch):
    plan, table, _, q0 = planned_pick(stances, 145, 1)
    _, _, soles, q_via, _ = via_and_pre(stances, 145, 1)
    heading, poses = plan.approach.heading, stances.poses
    # the straight blend from the stance to the via pose: the wrist passes under the edge
    assert _wrist_under(poses, [q0, q_via], table) < WRIST_CLEAR_M
    assert path_meets(poses, q0, q_via, heading, table)
    # without the wrists among the probes (as before) that blend passed
    monkeypatch.setattr(stances_module, "WRISTS", ())
    assert not path_meets(poses, q0, q_via, heading, table)
    monkeypatch.undo()
    around = detour_poses(poses, q0, q_via, soles, heading, np.zeros(2), plan.pelvis_z_m, plan.lean, table,
                          table.height_m + 2 * CLEAR_MARGIN_M, (), True, True)
    assert around
    chain = [q0, *around, q_via]
    assert not any(path_meets(poses, u, v, heading, table) for u, v in pairwise(chain))
    assert _wrist_under(poses, chain, table) >= WRIST_CLEAR_M
