"""The goal planner's own process (generator/goals/planner.py): the same plan as inline, the skill's
own refusal comes back as itself, beside a real-time thread the process runs at ordinary scheduling
in a scheduling group of its own that outweighs ordinary work, and a planner that died fails the goal that waited for it (the robot keeps its reference)."""

import os
from pathlib import Path

import numpy as np
import pytest

from g1_control.generator.goals.approach import plan_steps
from g1_control.generator.goals.context import GoalConfig, GoalContext, GoalFailed
from g1_control.generator.goals.planner import AUTOGROUP_NICE, PlannerProcess
from g1_control.generator.goals.poses import PosePlanner, ReachRefused, flat_soles
from g1_control.generator.goals.reach import reach_pose
from g1_control.generator.goals.stepping import Stance, SteppingConfig, walk_steps
from g1_control.scene import SceneConfig


@pytest.fixture(scope="module")
def poses():
    return PosePlanner()


def test_a_plan_made_in_the_planner_process_is_the_plan_made_inline(poses):
    q0 = poses.ik.nominal()
    cfg = SteppingConfig()
    steps = walk_steps(Stance.of(poses.ik, q0), np.array([0.3, 0.1]), 0.3, cfg, lambda xy: 0.0)
    planner = PlannerProcess()
    try:
        assert planner.started.result(timeout=60) != os.getpid()
        there = planner.submit(plan_steps, q0, steps, cfg).result(timeout=120)
        refused = planner.submit(reach_pose, q0, flat_soles(poses.ik, q0), "right", np.array([2.0, 0.0, 1.0]), 0.0)
        with pytest.raises(ReachRefused, match=r"right hand: the point is 2\.\d\d m from the shoulder"):
            refused.result(timeout=60)
    finally:
        planner.close()
    here = plan_steps(poses, q0, steps, cfg)
    assert len(steps) >= 3
    np.testing.assert_allclose(there.trajectory.q_rad, here.trajectory.q_rad, atol=1e-9)
    np.testing.assert_allclose(there.feet_w_m, here.feet_w_m, atol=1e-9)


def test_beside_a_real_time_thread_the_planner_runs_at_ordinary_scheduling_in_a_heavy_group_of_its_own():
    before = os.sched_getscheduler(0), os.sched_getparam(0)
    os.sched_setscheduler(0, os.SCHED_RR, os.sched_param(12))  # as g1 deploy runs its threads (root here)
    try:
        planner = PlannerProcess()
        assert (os.sched_getscheduler(0), os.sched_getparam(0).sched_priority) == (os.SCHED_RR, 12)
    finally:
        os.sched_setscheduler(0, *before)
    try:
        pid = planner.started.result(timeout=60)
        assert os.sched_getscheduler(pid) == os.SCHED_OTHER  # every real-time thread preempts it
        assert os.getsid(pid) != os.getsid(0)
        assert Path(f"/proc/{pid}/autogroup").read_text().endswith(f" nice {AUTOGROUP_NICE}\n")
    finally:
        planner.close()


def test_a_planner_that_died_fails_the_goal_waiting_for_it():
    ctx = GoalContext(SceneConfig(), GoalConfig(plan_in_background=True))
    assert ctx.planner is not None
    ctx.planner.started.result(timeout=60)
    ctx.planner._process.kill()
    ctx.planner._process.wait()
    job = ctx.compute("stand", PosePlanner.stand, ctx.poses.ik.nominal(), [], 0.7, np.zeros(29))
    with pytest.raises(GoalFailed, match=r"^stand: the goal planner process ended \(exit code -9\)$"):
        for _ in range(1000):
            next(job)
    ctx.close()
