"""Platforms: step up onto a platform (or a step) from in front of its nearest side, and back down
to where the step up started, then straight back until the stance is clear of it (the walking
policy that takes over knows nothing of the platform)."""

from __future__ import annotations

import math
from collections.abc import Generator, Iterator

import numpy as np

from g1_control.generator.goals.approach import correct_stance, enter_whole_body, plan_steps, step_to, walk_to
from g1_control.generator.goals.box import Approach
from g1_control.generator.goals.context import GoalContext, GoalFailed
from g1_control.generator.goals.stepping import SOLE_HALF_LENGTH_M, Stance, level_steps
from g1_control.scene import Block
from g1_control.types import PHASE_WHOLE_BODY, TaskGoal


def find_platform(ctx: GoalContext, name: str | None) -> Generator[None, None, Block]:
    """The platform `name` (None: the nearest within 4 m). One the scene does not hold yet is waited for,
    standing, up to GoalConfig.sight_wait_s (perception may see it: GoalContext.see_platform); then the
    goal refuses, naming it, before anything moves."""
    t0 = ctx.t
    while True:
        block = _platform(ctx, name)
        if block is not None:
            return block
        if ctx.t - t0 >= ctx.config.sight_wait_s:
            break
        yield
    known = ", ".join(p.name for p in ctx.scene.platforms) or "none"
    seen = ", ".join(sorted(ctx.platforms_seen)) or "none"
    what = f"platform '{name}' has never been seen" if name is not None else "no platform within 4 m has been seen"
    raise GoalFailed(f"{what}: the launch file's scene does not hold it and perception has not seen it in "
                     f"{ctx.config.sight_wait_s:g} s (platforms known: {known}; seen by perception: {seen}); "
                     "nothing moved for this goal")


def _platform(ctx: GoalContext, name: str | None) -> Block | None:
    """The platform `name` or the nearest within 4 m, None while the scene holds none; GoalFailed for a name
    that is a table or a box."""
    if name is not None:
        block = ctx.scene.block(name)
        if block is None and name not in ctx.scene.names():
            return None
        if block is None or block not in ctx.scene.platforms:
            raise GoalFailed(f"'{name}' is not a platform of the scene")
        return block
    _, pos_w = ctx.world_pose()
    here = pos_w[:2]
    best = min(ctx.scene.platforms, key=lambda p: p.distance_xy(here), default=None)
    return None if best is None or best.distance_xy(here) > 4.0 else best


def step_up(ctx: GoalContext, goal: TaskGoal) -> Iterator[None]:
    cfg = ctx.config
    if ctx.on_platform is not None:
        raise GoalFailed(f"already on '{ctx.on_platform}'")
    block = yield from find_platform(ctx, goal.target)
    _, pos_w = ctx.world_pose()
    start_xy = pos_w[:2].copy()
    mid, heading, depth_m = _front(block, start_xy, cfg.toe_gap_m)
    if depth_m < cfg.past_edge_m + SOLE_HALF_LENGTH_M + 0.05:
        raise GoalFailed(f"platform '{block.name}' is too shallow to stand on")
    _record(ctx, block)
    approach = Approach(mid, heading)
    if ctx.phase != PHASE_WHOLE_BODY:
        yield from walk_to(ctx, approach, out_m=cfg.approach_offset_m)
        yield from enter_whole_body(ctx)
    seen = ctx.scene.block(block.name)
    if seen is not None and seen is not block:  # perception placed it again while the robot walked: aim there
        block = seen
        mid, heading, _ = _front(block, start_xy, cfg.toe_gap_m)
        _record(ctx, block)
    yield from step_to(ctx, mid + ctx.offset(), heading, cfg.steps, name="approach")
    yield from correct_stance(ctx, mid, heading, cfg.steps, tolerance_m=0.02)
    q0 = ctx.hold_q()
    stance = Stance.of(ctx.ik, q0)
    forward = SOLE_HALF_LENGTH_M + cfg.toe_gap_m + cfg.past_edge_m
    steps = level_steps(stance, forward, block.height_m, cfg.steps)
    plan = yield from ctx.compute("step up", plan_steps, q0, steps, cfg.steps, None, None, None, "step up")
    yield from ctx.run(plan.trajectory)
    ctx.on_platform = block.name
    ctx.step_back = (forward, 0.0)


def _front(block: Block, from_xy: np.ndarray, toe_gap_m: float) -> tuple[np.ndarray, float, float]:
    """(mid-point, heading) of the stance squarely in front of the side of `block` that faces `from_xy`,
    clear of its corners, the toes `toe_gap_m` short of the edge; and the platform's depth from that side."""
    local = block.local_xy(from_xy)
    ratios = np.abs(local) / block.half
    axis = int(np.argmax(ratios))
    other = 1 - axis
    n_local = np.zeros(2)
    n_local[axis] = math.copysign(1.0, local[axis])
    along = float(np.clip(local[other], -block.half[other] + 0.3, block.half[other] - 0.3))
    edge_local = np.zeros(2)
    edge_local[axis] = n_local[axis] * block.half[axis]
    edge_local[other] = along
    c, sn = math.cos(block.yaw_rad), math.sin(block.yaw_rad)
    rot = np.array([[c, -sn], [sn, c]])
    normal, edge = rot @ n_local, block.center + rot @ edge_local
    mid = edge + normal * (SOLE_HALF_LENGTH_M + toe_gap_m)
    return mid, math.atan2(-normal[1], -normal[0]), float(block.half[axis] * 2)


def _record(ctx: GoalContext, block: Block) -> None:
    ctx.info.update(platform=block.name, height_m=block.height_m, platform_center_xy_m=block.center.tolist(),
                    platform_from="perception" if block.name in ctx.platforms_seen else "the launch file's scene")


def step_down(ctx: GoalContext, goal: TaskGoal) -> Iterator[None]:
    """Step back down (and clear of the platform); the executor then hands back to the walking policy."""
    cfg = ctx.config
    if ctx.on_platform is None:
        raise GoalFailed("not standing on a platform")
    ctx.info.update(platform=ctx.on_platform)
    forward, _ = ctx.step_back
    q0 = ctx.hold_q()
    stance = Stance.of(ctx.ik, q0)
    back = stance.mid_xy - forward * np.array([math.cos(stance.heading), math.sin(stance.heading)])
    level = ctx.scene.ground_height(back - ctx.offset())
    if level > 0.0:
        level = 0.0
    steps = level_steps(stance, -forward, level, cfg.steps)
    plan = yield from ctx.compute("step down", plan_steps, q0, steps, cfg.steps, None, None, None, "step down")
    yield from ctx.run(plan.trajectory)
    block = ctx.scene.block(ctx.on_platform)
    ctx.on_platform = None
    if block is not None:
        yield from clear_of(ctx, block)


def clear_of(ctx: GoalContext, block: Block) -> Iterator[None]:
    """Step straight back until the stance's mid-point is `clear_of_platform_m` from `block`."""
    cfg = ctx.config
    stance = Stance.of(ctx.ik, ctx.hold_q())
    gap = block.distance_xy(stance.mid_xy - ctx.offset())
    back_m = cfg.clear_of_platform_m - gap
    if back_m < 0.01:
        return
    ctx.note(f"{gap * 100:.0f} cm from '{block.name}': stepping {back_m * 100:.0f} cm back clear of it")
    back = stance.mid_xy - back_m * np.array([math.cos(stance.heading), math.sin(stance.heading)])
    yield from step_to(ctx, back, stance.heading, cfg.steps, name="clear of the platform", first_back_m=back_m)
