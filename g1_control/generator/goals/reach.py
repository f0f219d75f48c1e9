"""Reach: a hand (or both) to a point in the world or an offset from where the hand stands, from
the stance the robot is in; the pose is held `reach_hold_s` and the robot stays under the
whole-body controller afterwards (it holds the point until the next command moves it)."""

from __future__ import annotations

import math
from collections.abc import Iterator

import numpy as np

from g1_control.generator.goals.approach import enter_whole_body
from g1_control.generator.goals.context import ARMS, GoalContext
from g1_control.generator.goals.poses import PosePlanner, PoseResult, ReachRefused, Sole, flat_soles, stance_heading
from g1_control.generator.whole_body import keyframe_trajectory
from g1_control.robot import g1
from g1_control.types import PHASE_WHOLE_BODY, TaskGoal


def reach_pose(poses: PosePlanner, q0: np.ndarray, soles: list[Sole], hand: str, target: np.ndarray,
               heading: float) -> PoseResult:
    """The pose with `hand` ("left", "right", "both") at `target` (a planner job: GoalContext.compute)."""
    if hand == "both":
        lateral = np.array([-math.sin(heading), math.cos(heading), 0.0])
        res = poses.hands_on(q0, soles, (target + 0.1 * lateral, target - 0.1 * lateral), heading)
        if res.residual_m > 0.03:
            raise ReachRefused(f"both hands: the closest pose leaves a hand {res.residual_m * 100:.1f} cm off")
        return res
    return poses.reach(q0, soles, 0 if hand == "left" else 1, target)


def reach(ctx: GoalContext, goal: TaskGoal) -> Iterator[None]:
    cfg = ctx.config
    if ctx.phase != PHASE_WHOLE_BODY:
        yield from enter_whole_body(ctx)
    q0 = ctx.hold_q()
    soles = flat_soles(ctx.ik, q0)
    heading = stance_heading(soles)
    off = np.append(ctx.offset(), 0.0)
    if goal.pos_w_m is not None:
        target = np.asarray(goal.pos_w_m, dtype=float) + off
    else:
        assert goal.offset_h_m is not None
        standing = q0.copy()  # the hand's standing position: arms at the default pose
        standing[7 + ARMS] = g1.DEFAULT_Q_RAD[ARMS]
        base = ctx.poses.hand_point(standing, 0 if goal.hand == "left" else 1)
        c, s = math.cos(heading), math.sin(heading)
        o = goal.offset_h_m
        target = base + np.array([c * o[0] - s * o[1], s * o[0] + c * o[1], o[2]])
    res = yield from ctx.compute("reach", reach_pose, q0, soles, goal.hand, target, heading)
    ctx.note(f"reach: {res.mode}, hand {res.residual_m * 100:.1f} cm from the point in the plan")
    move = cfg.move_s * max(1.0, float(np.abs(res.q[7:] - q0[7:]).max()) / 1.5)
    ctx.info.update(hand=goal.hand, target_w_m=(target - off).tolist(), mode=res.mode,
                    frame="world" if ctx.localised else "stance",
                    plan_residual_m=res.residual_m, hold_s=(ctx.t + move, ctx.t + move + cfg.reach_hold_s))
    yield from ctx.run(keyframe_trajectory("reach", [(0.0, q0), (move, res.q), (move + cfg.reach_hold_s, res.q)]),
                       keep=True)
