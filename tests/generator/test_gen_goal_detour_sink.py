"""A detour around a support's top keeps the pelvis near the hold's height (stances.DETOUR_SINK_M):
`g1 bench objects` 153.19 (a 1.7 kg box on a 0.90 m table, standing) fell at the pick on main, the
first poses of its way around solved with the pelvis at 0.26 m (the IK lost its branch), so the
reference pelvis went down toward the floor (traced: 0.74 -> 0.33 m in 2 s)."""

import math

import numpy as np
import pytest

from g1_control.generator.goals import stances as stances_module
from g1_control.generator.goals.poses import PosePlanner
from g1_control.generator.goals.stances import CLEAR_MARGIN_M, DETOUR_SINK_M, StancePlanner, detour_poses
from tests.generator.bench_picks import planned_pick, via_and_pre


@pytest.fixture(scope="module")
def stances():
    return StancePlanner(PosePlanner())


def test_a_way_around_that_drops_the_pelvis_is_not_kept(stances, monkeypatch):
    plan, table, _, q0 = planned_pick(stances, 153, 19)
    _, _, soles, q_via, _ = via_and_pre(stances, 153, 19)
    assert plan.pelvis_z_m > 0.7  # standing

    def around():
        return detour_poses(stances.poses, q0, q_via, soles, plan.approach.heading, np.zeros(2), plan.pelvis_z_m,
                            plan.lean, table, table.height_m + 2 * CLEAR_MARGIN_M, (), True, True)

    chain = around()
    assert chain and min(float(q[2]) for q in chain) >= plan.pelvis_z_m - DETOUR_SINK_M
    monkeypatch.setattr(stances_module, "DETOUR_SINK_M", math.inf)  # as before: the first clean way kept
    before = around()
    assert min(float(q[2]) for q in before) < 0.3
