"""A whole-body plan pauses while the loop stalls (GoalConfig.plan_pause_after_s): of a gap between two
ticks' states longer than the command's life, only the life plays, so the plan resumes where the robot
link held the robot; with the pause off the plan plays on through the stall. Driven kinematically
(tests/generator/test_gen_goal_executor.py: the robot is where the plan says)."""

from __future__ import annotations

import numpy as np
import pytest

from g1_control.generator.goals.executor import GoalConfig, GoalGenerator
from g1_control.types import PHASE_WHOLE_BODY, Command, TaskGoal
from tests.generator.test_gen_goal_executor import DT, Walking, _scene, _state, _tick

STALL_S = 0.2


def _reach_under_way(after_s: float):
    """A reach played 0.3 s into its plan; (generator, walking side, state, the plan time played)."""
    inner = Walking()
    gen = GoalGenerator(inner, _scene(), GoalConfig(plan_pause_after_s=after_s))
    state = _state()
    reach = TaskGoal("reach", goal_id="r", hand="left", offset_h_m=np.array([0.15, 0.05, 0.15]))
    k = 0
    while not (gen.phase == PHASE_WHOLE_BODY and state.t_s - gen.ctx.plan_t0 >= 0.3):
        state.t_s = k * DT
        _tick(gen, inner, state, Command(tasks=[reach]))
        k += 1
        assert k < 3000, "the reach never started"
    return gen, inner, state, reach, state.t_s - gen.ctx.plan_t0


@pytest.mark.parametrize("after_s", [0.03, 0.0])
def test_a_stall_plays_only_the_command_life_of_the_plan(after_s):
    gen, inner, state, reach, played = _reach_under_way(after_s)
    plan = gen.ctx.plan
    assert plan.duration_s > played + STALL_S + 0.1, "the reach's plan must outlast the stall"
    moved = np.abs(plan.sample(played + STALL_S).q_rad - plan.sample(played + 0.03).q_rad).max()
    assert moved > 1e-3, "the plan must move within the stall for this test to tell"
    state.t_s += STALL_S  # the loop stalled: the next state comes 200 ms later
    _tick(gen, inner, state, Command(tasks=[reach]))
    expected = played + (after_s if after_s > 0 else STALL_S)
    np.testing.assert_allclose(gen.joint_reference(state.t_s).q_rad, plan.sample(expected).q_rad, atol=1e-9)
    assert gen.ctx.plan is plan
    if after_s > 0:
        assert gen.ctx.stalls == 1 and gen.ctx.stalled_s == pytest.approx(STALL_S - after_s)
        assert "the loop stalled 200 ms: the plan paused 170 ms of it" in [text for _, text in gen.log]
    else:
        assert gen.ctx.stalls == 0


def test_ticks_at_the_loop_rate_never_pause_a_plan():
    gen, inner, state, reach, _ = _reach_under_way(0.03)
    plan, t0 = gen.ctx.plan, gen.ctx.plan_t0
    for _ in range(10):
        state.t_s += DT * 2.5  # late ticks, but within the command's life
        _tick(gen, inner, state, Command(tasks=[reach]))
    assert gen.ctx.plan is plan and gen.ctx.plan_t0 == t0 and gen.ctx.stalls == 0
