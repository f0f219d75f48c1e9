"""Step goals onto platforms perception sees (generator/goals/platform.py, GoalContext.see_platform),
driven kinematically (test_gen_goal_executor's robot: the base moves as commanded): a platform the launch
file's scene does not list is stepped onto once perception has seen it; one it lists at a wrong place is
where perception sees it; one never seen refuses, naming it, with nothing moved; the launch file's scene
is left as written."""

from __future__ import annotations

import numpy as np
import pytest

from g1_control.generator.goals.executor import FAILED, GoalConfig, GoalGenerator
from g1_control.scene import Platform, SceneConfig, Table
from g1_control.types import PHASE_LOCOMOTION, Command, TaskGoal
from tests.generator.test_gen_goal_executor import DT, Walking, _state, _tick

SEEN = Platform("step", (1.5, -0.4), (0.7, 1.2), 0.15, yaw_rad=0.1)


def _run(gen: GoalGenerator, inner: Walking, goal: TaskGoal, seconds: float, sees=None):
    """Tick `gen` for `seconds` with `goal`; `sees(t)`: the platforms perception sees at t (scene frame)."""
    state = _state()
    walked = []
    for k in range(int(seconds / DT)):
        state.t_s = k * DT
        if sees is not None:
            gen._perceive({}, sees(state.t_s))
        _tick(gen, inner, state, Command(tasks=[goal]))
        walked.append(np.array(gen.ctx.walk))
        if goal.goal_id in gen.goal_status:
            break
    return state, np.array(walked)


def test_a_platform_never_seen_refuses_naming_it_and_nothing_moves():
    inner = Walking()
    scene = SceneConfig(tables=[Table("table", (1.2, 1.5), (0.5, 0.8), 0.7)])
    gen = GoalGenerator(inner, scene, GoalConfig(sight_wait_s=1.0))
    state, walked = _run(gen, inner, TaskGoal("step_up", goal_id="up", target="step"), 3.0)
    assert gen.goal_status == {"up": FAILED}
    assert gen.goal_messages["up"] == (
        "platform 'step' has never been seen: the launch file's scene does not hold it and perception has not "
        "seen it in 1 s (platforms known: none; seen by perception: none); nothing moved for this goal")
    assert 0.99 <= gen.goal_info["up"]["end_s"] - gen.goal_info["up"]["start_s"] <= 1.02  # it waited, standing
    assert not np.any(walked) and np.allclose(state.base_pos_w_m[:2], 0.0) and gen.phase == PHASE_LOCOMOTION


@pytest.mark.parametrize(("listed", "seen_from_s"), [([], 0.5), ([Platform("step", (1.8, 0.3), (0.7, 1.2), 0.15)], 0.0)],
                         ids=["not listed, seen after the goal started", "listed at a wrong place"])
def test_a_step_goal_goes_to_the_platform_where_perception_sees_it(listed, seen_from_s):
    inner = Walking()
    scene = SceneConfig(platforms=list(listed))
    gen = GoalGenerator(inner, scene, GoalConfig())
    state, walked = _run(gen, inner, TaskGoal("step_up", goal_id="up", target="step"), 3.0,
                         sees=lambda t: {"step": SEEN} if t >= seen_from_s else {})
    info = gen.goal_info["up"]
    assert "up" not in gen.goal_status, gen.goal_messages  # under way
    assert info["platform"] == "step" and info["platform_from"] == "perception"
    assert info["platform_center_xy_m"] == pytest.approx([1.5, -0.4]) and info["height_m"] == 0.15
    assert not np.any(walked[:int(seen_from_s / DT)])  # unseen: standing
    # then walking to its near side (the -x side, which faces the robot), not to where the scene listed it
    assert walked[:, 0].max() > 0.1 and 0.3 < state.base_pos_w_m[0] < 1.0 and state.base_pos_w_m[1] < -0.1
    assert scene.platforms == listed and gen.scene.platforms == [SEEN]  # the launch file's scene as written


def test_perception_does_not_turn_a_table_into_a_platform():
    scene = SceneConfig(tables=[Table("table", (1.2, 1.5), (0.5, 0.8), 0.7)])
    gen = GoalGenerator(Walking(), scene, GoalConfig())
    gen._perceive({}, {"table": Platform("table", (1.0, 0.0), (0.7, 1.2), 0.15)})
    assert gen.scene.platforms == [] and gen.ctx.platforms_seen == set()
