"""A pick's stance keeps the arms out from under a support's top while the robot steps in (upright,
the arms swung back: stances.ARMS_BACK), not only in the hold pose it then bends to: `g1 bench
objects` 157.4 (a 3.9 kg box on a 0.86 m table) fell at the pick on main, its right elbow and wrist
under the top's edge from the last steps on (traced: the elbow against the underside); the search now
refuses it. 158.13 (first run after the change) keeps another stance and is placed."""

import math

import pytest

from g1_control.generator.goals import stances as stances_module
from g1_control.generator.goals.poses import PosePlanner
from g1_control.generator.goals.stances import StancePlanner, path_meets
from tests.generator.bench_picks import planned_pick


@pytest.fixture(scope="module")
def stances():
    return StancePlanner(PosePlanner())


def test_the_stance_kept_steps_in_with_the_arms_clear_of_the_top(stances, monkeypatch):
    # bench objects 158.13 (2.6 kg on a 0.85 m table): the stance the search keeps steps in clear ...
    plan, table, _, stand = planned_pick(stances, 158, 13)
    assert not path_meets(stances.poses, stand, stand, plan.approach.heading, table, tips=False)
    # ... where, without the check, it kept one whose arms step in under the top's edge
    real = stances_module.path_meets
    monkeypatch.setattr(stances_module, "path_meets",
                        lambda poses, q_a, q_b, *a, **k: False if q_a is q_b else real(poses, q_a, q_b, *a, **k))
    before, _, _, stand_before = planned_pick(stances, 158, 13)
    assert abs(math.remainder(before.approach.heading - plan.approach.heading, 2 * math.pi)) > 0.1
    assert real(stances.poses, stand_before, stand_before, before.approach.heading, table, tips=False)
