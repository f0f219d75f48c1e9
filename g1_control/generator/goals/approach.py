"""Approach: from walking to a work stance.

The walking policy walks to a stance short of the work (velocity commands closed on the robot's
measured world pose) and stands still until it has settled (`walk_to`); the whole-body controller
takes over from the measured configuration (`enter_whole_body`: the soles where they are, so the
hand-over does not jump) and steps the rest (`step_to`), correcting the stance against the world
pose until it is where it should be (`correct_stance`).

Holding something, where the tracker has a gait of its own (GoalConfig.walk_while_holding: the
whole-body controller), a goal walks in that gait with the upper body held (`walk_holding`: back off,
then turn, walk straight, turn, `turn_walk_turn`) and comes back under a whole-body plan standing
(`stand_holding`), from where the steps into the stance start.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator

import numpy as np

from g1_control.generator.goals.box import Approach
from g1_control.generator.goals.context import GoalContext, GoalFailed
from g1_control.generator.goals.poses import PosePlanner, flat_soles, stance_heading
from g1_control.generator.goals.stepping import (
    Footstep,
    Stance,
    SteppingConfig,
    SteppingPlan,
    stepping_trajectory,
    walk_steps,
)
from g1_control.generator.whole_body import keyframe_trajectory
from g1_control.robot import g1
from g1_control.rotations import wrap_angle, yaw_of
from g1_control.types import PHASE_LOCOMOTION


def plan_steps(poses: PosePlanner, q0: np.ndarray, steps: list[Footstep], cfg: SteppingConfig,
               posture: np.ndarray | None = None, forces: np.ndarray | None = None,
               com_shift: np.ndarray | None = None, name: str = "steps") -> SteppingPlan:
    """The whole-body reference of `steps` from q0 (stepping_trajectory; a planner job: GoalContext.compute)."""
    return stepping_trajectory(poses.ik, q0, steps, cfg, posture=posture, hand_forces=forces,
                               com_offset_h_m=com_shift, name=name)


def enter_whole_body(ctx: GoalContext) -> Iterator[None]:
    """From walking: a reference from the measured pose to a clean standing one."""
    q = ctx.measured_q()
    soles = flat_soles(ctx.ik, q)
    # without a world pose the scene cannot be placed under the feet: the robot stands on the floor
    ground = [ctx.scene.ground_height(p[:2]) if ctx.localised else 0.0 for p, _ in soles]
    lift = min(p[2] - g for (p, _), g in zip(soles, ground))
    q[2] -= lift  # the lower sole exactly on its ground
    soles = [(np.array([p[0], p[1], g]), r) for (p, r), g in zip(soles, ground)]
    q_stand = yield from ctx.compute("stand", PosePlanner.stand, q, soles, min(ground) + ctx.poses.nominal_pelvis_m,
                                     g1.DEFAULT_Q_RAD)
    ctx.note("hand over to the whole-body controller")
    yield from ctx.run(keyframe_trajectory("stand", [(0.0, q), (ctx.config.stand_s, q_stand)]))


def walk_to(ctx: GoalContext, approach: Approach, *, out_m: float) -> Iterator[None]:
    """Walk (the policy) to `out_m` short of the approach stance, facing it, then stand still."""
    cfg = ctx.config
    fwd = np.array([math.cos(approach.heading), math.sin(approach.heading)])
    goal_xy = approach.pelvis_xy() - out_m * fwd
    t0 = ctx.t
    ctx.info["stage"] = "walk"
    settled_since: float | None = None
    arrived = False
    while True:
        s, pos_w = ctx.world_pose()
        if ctx.t - t0 > cfg.walk_timeout_s:
            raise GoalFailed(f"did not reach the stance within {cfg.walk_timeout_s:.0f} s")
        yaw = yaw_of(s.imu_quat_wxyz)
        d = goal_xy - pos_w[:2]
        dist = float(np.hypot(*d))
        yaw_err = float(wrap_angle(approach.heading - yaw))
        c, sn = math.cos(yaw), math.sin(yaw)
        d_h = np.array([c * d[0] + sn * d[1], -sn * d[0] + c * d[1]])
        arrived = arrived or (dist <= cfg.approach_tolerance_m and abs(yaw_err) <= cfg.approach_heading_tolerance_rad)
        if arrived:
            # stand until settled, then judge the distance again (GoalConfig.approach_settled_tolerance_m)
            ctx.walk[:] = 0.0
            speed = float(np.hypot(*s.base_linvel_w_mps[:2])) if s.base_linvel_w_mps is not None else 0.0
            settled_since = ctx.t if settled_since is None or speed > cfg.settle_speed_mps else settled_since
            if ctx.t - settled_since >= cfg.settle_s:
                if dist <= cfg.approach_settled_tolerance_m and abs(yaw_err) <= cfg.approach_settled_heading_tolerance_rad:
                    return
                arrived = False  # it drifted off: walk again
            else:
                yield
                continue
        settled_since = None
        if dist > 0.5:
            bearing_err = float(wrap_angle(math.atan2(d[1], d[0]) - yaw))
            vx = min(cfg.walk_speed_mps, 0.8 * dist) * max(0.0, math.cos(bearing_err)) ** 2
            ctx.walk[:] = (vx, 0.0, float(np.clip(1.5 * bearing_err, -cfg.turn_rate_radps, cfg.turn_rate_radps)))
        else:
            v = np.clip(1.2 * d_h, -0.25, 0.25)
            v[np.abs(d_h) < 0.02] = 0.0
            v = np.where((v != 0) & (np.abs(v) < 0.1), np.sign(v) * 0.1, v)
            wz = float(np.clip(1.5 * yaw_err, -cfg.turn_rate_radps, cfg.turn_rate_radps))
            if 0 < abs(wz) < 0.15 and abs(yaw_err) > cfg.approach_heading_tolerance_rad * 0.5:
                wz = math.copysign(0.15, wz)
            ctx.walk[:] = (v[0], v[1], wz)
        yield


def back_off(ctx: GoalContext, distance_m: float, speed_mps: float = 0.2) -> Iterator[None]:
    """Walk straight back `distance_m` (ctx.walk, the tracker's gait) from where the robot stands, closed on
    its world pose; GoalFailed when it has not within GoalConfig.walk_timeout_s."""
    s, start = ctx.world_pose()
    yaw = yaw_of(s.imu_quat_wxyz)
    back = -np.array([math.cos(yaw), math.sin(yaw)])
    t0 = ctx.t
    while True:
        _, pos_w = ctx.world_pose()
        if float((pos_w[:2] - start[:2]) @ back) >= distance_m:
            break
        if ctx.t - t0 > ctx.config.walk_timeout_s:
            raise GoalFailed(f"did not back off {distance_m:.2f} m within {ctx.config.walk_timeout_s:.0f} s")
        ctx.walk[:] = (-speed_mps, 0.0, 0.0)
        yield
    ctx.walk[:] = 0.0


def walk_holding(ctx: GoalContext, approach: Approach, carry_q: np.ndarray, *, out_m: float,
                 back_m: float = 0.0) -> Iterator[None]:
    """Walk holding something (GoalConfig.walk_while_holding: the tracker's own gait, the upper body
    held at carry_q, what is held in the controller's dynamics; the executor's holding reference) to
    `out_m` short of `approach` (less where that point lies within WALK_CLEAR_M of a table or platform),
    facing it, backing off `back_m` first. The caller then stands holding it under a whole-body plan
    again (stand_holding), where the steps into the stance start."""
    ctx.carry_q = np.asarray(carry_q, dtype=float).copy()
    ctx.phase = PHASE_LOCOMOTION
    ctx.plan = None
    if back_m > 0:
        yield from back_off(ctx, back_m)
    fwd = np.array([math.cos(approach.heading), math.sin(approach.heading)])
    blocks = (*ctx.scene.tables, *ctx.scene.platforms)
    while out_m > 0 and any(b.distance_xy(approach.pelvis_xy() - out_m * fwd) < WALK_CLEAR_M for b in blocks):
        out_m = max(0.0, out_m - 0.05)
    yield from turn_walk_turn(ctx, approach, out_m=out_m)


GAIT_PELVIS_DROP_M = 0.06
"""Walking by the whole-body controller's own gait (GoalConfig.walk_while_holding), the pelvis goes this
much below its standing height at most: the gait holds the CoM 0.03 m lower, and 0.05 m more per m/s up
to 0.6 m/s (trackers/wbc/tracker.py, WbcConfig.walking_com_lower_m and its speed terms)."""


WALK_CLEAR_M = 0.25
"""walk_holding stops no nearer than this to a table's or platform's outline (the pelvis point): short of a
table's stance, 0.2 m back from it lay 6 cm from another table, whose edge the pelvis met while the robot
stood there; it fell in the steps in (bench bottle --carry seed 19 trial 19, measured)."""


def turn_walk_turn(ctx: GoalContext, approach: Approach, *, out_m: float) -> Iterator[None]:
    """Walk to `out_m` short of the approach stance one motion at a time: turn on the spot to face the
    point, walk straight to it, turn on the spot to the stance's heading, stand until settled (at most
    GoalConfig.carry_walk_speed_mps, carry_turn_rate_radps). Holding a bottle in one hand, walk_to's
    last half metre (sideways and turning at once, its commands switching as the pose sways) threw the
    robot sideways and it fell (bench bottle --carry seed 19 trial 19, measured; this walk there gets to
    its point); the steps into the stance (step_to) take the few centimetres left. GoalFailed after
    GoalConfig.walk_timeout_s."""
    cfg = ctx.config
    fwd = np.array([math.cos(approach.heading), math.sin(approach.heading)])
    goal_xy = approach.pelvis_xy() - out_m * fwd
    t0 = ctx.t
    ctx.info["stage"] = "walk holding"
    stage = "face"
    settled_since: float | None = None
    while True:
        if ctx.t - t0 > cfg.walk_timeout_s:
            raise GoalFailed(f"did not reach the stance within {cfg.walk_timeout_s:.0f} s (walking holding, {stage})")
        s, pos_w = ctx.world_pose()
        yaw = yaw_of(s.imu_quat_wxyz)
        d = goal_xy - pos_w[:2]
        dist = float(np.hypot(*d))
        bearing_err = float(wrap_angle(math.atan2(d[1], d[0]) - yaw))
        if stage == "face":
            if dist <= cfg.approach_tolerance_m:
                stage = "turn"
            elif abs(bearing_err) <= FACE_TOLERANCE_RAD:
                stage = "walk"
        if stage == "walk" and (dist <= cfg.approach_tolerance_m or abs(bearing_err) > math.pi / 2):
            stage = "turn"  # there, or past it
        elif stage == "walk" and abs(bearing_err) > REFACE_RAD:
            stage = "face"  # the point inside the walk's turning circle: face it again on the spot
        if stage == "turn" and abs(wrap_angle(approach.heading - yaw)) <= cfg.approach_heading_tolerance_rad / 2:
            stage = "settle"
        if stage == "face":
            ctx.walk[:] = (0.0, 0.0, float(np.clip(1.5 * bearing_err, -cfg.carry_turn_rate_radps, cfg.carry_turn_rate_radps)))
        elif stage == "walk":
            vx = float(np.clip(0.8 * dist, 0.1, cfg.carry_walk_speed_mps))
            wz = float(np.clip(1.5 * bearing_err, -cfg.carry_turn_rate_radps / 2, cfg.carry_turn_rate_radps / 2))
            ctx.walk[:] = (vx, 0.0, wz)
        elif stage == "turn":
            yaw_err = float(wrap_angle(approach.heading - yaw))
            wz = float(np.clip(1.5 * yaw_err, -cfg.carry_turn_rate_radps, cfg.carry_turn_rate_radps))
            ctx.walk[:] = (0.0, 0.0, math.copysign(max(abs(wz), 0.15), wz))
        else:
            ctx.walk[:] = 0.0
            speed = float(np.hypot(*s.base_linvel_w_mps[:2])) if s.base_linvel_w_mps is not None else 0.0
            settled_since = ctx.t if settled_since is None or speed > cfg.settle_speed_mps else settled_since
            if ctx.t - settled_since >= cfg.settle_s:
                return
        yield


FACE_TOLERANCE_RAD = 0.15
"""turn_walk_turn walks once it faces its point within this."""
REFACE_RAD = 0.5
"""... and faces it again, on the spot, once it is off its point's bearing by more than this: walking at
carry_walk_speed_mps, turning at most carry_turn_rate_radps / 2, the robot cannot turn tighter than a
1.25 m radius; a point it passed close beside it circled (the pick-and-place scene 145.0 on the tracking
layer: 0.14-0.31 m from the point, 2.5 s at the full turn, until a hip over-speed trip; measured)."""


def stand_holding(ctx: GoalContext, shift: np.ndarray | None = None,
                  forces: Callable[[float], np.ndarray] | None = None) -> Iterator[None]:
    """From walking holding something (ctx.carry_q) back under a whole-body plan: from the measured legs
    and the held arms to a clean standing pose at the nominal height, the held weight ahead balanced
    (the CoM shifted by `shift`, heading frame); forces(heading): the hands' forces in it (None: the
    executor's own, a bottle's). A place's footsteps start from it (its steps from the walking height
    rose 5 cm at once, and the robot fell with the box, measured)."""
    assert ctx.carry_q is not None
    q = ctx.measured_q()
    legs = len(g1.LEG_JOINTS)
    q[7 + legs:] = ctx.carry_q[legs:]
    soles = flat_soles(ctx.ik, q)
    ground = [ctx.scene.ground_height(p[:2]) if ctx.localised else 0.0 for p, _ in soles]
    q[2] -= min(p[2] - g for (p, _), g in zip(soles, ground))  # the lower sole on its ground
    soles = [(np.array([p[0], p[1], g]), r) for (p, r), g in zip(soles, ground)]
    q_stand = yield from ctx.compute("stand holding", PosePlanner.stand, q, soles,
                                     min(ground) + ctx.poses.nominal_pelvis_m, q[7:].copy(),
                                     np.zeros(2) if shift is None else shift)
    ctx.carry_q = None
    held_name = ctx.held.box.name if ctx.held is not None else \
        ctx.held_bottle.bottle.name if ctx.held_bottle is not None else "nothing"
    ctx.note(f"stand holding '{held_name}'")
    hand_forces = None
    if forces is not None:
        held = forces(stance_heading(soles))
        hand_forces = lambda tk: held
    yield from ctx.run(keyframe_trajectory("hold", [(0.0, q), (ctx.config.move_s, q_stand)],
                                           hand_forces=hand_forces), keep=True)


def step_to(ctx: GoalContext, mid_xy: np.ndarray, heading: float, cfg: SteppingConfig, *, posture=None, forces=None,
            com_shift=None, first_back_m: float = 0.0, name: str = "steps") -> Iterator[None]:
    q0 = ctx.hold_q()
    stance = Stance.of(ctx.ik, q0)
    ground = ctx.scene.ground_height
    steps = []
    if first_back_m > 0:
        back = stance.mid_xy - first_back_m * np.array([math.cos(stance.heading), math.sin(stance.heading)])
        steps += walk_steps(stance, back, stance.heading, cfg, lambda xy: ground(xy), backward_max_m=1.0)
        for st in steps:
            stance = stance.apply(st)
    steps += walk_steps(stance, mid_xy, heading, cfg, lambda xy: ground(xy), then=steps)
    if not steps:
        return
    plan = yield from ctx.compute(name, plan_steps, q0, steps, cfg, posture, forces, com_shift, name)
    ctx.last_steps = plan
    if plan.sole_error_m > 0.03:
        raise GoalFailed(f"{name}: the footsteps are out of the legs' reach (plan off by "
                         f"{plan.sole_error_m * 100:.0f} cm)")
    yield from ctx.run(plan.trajectory)


def correct_stance(ctx: GoalContext, mid_w: np.ndarray, heading: float, cfg: SteppingConfig, *, posture=None,
                   forces=None, com_shift=None, tolerance_m: float = 0.03, rounds: int = 2) -> Iterator[None]:
    """Small steps until the stance is where it should be in the world (the tracker's odometry
    drifts a few cm per metre walked; the world pose says where the robot really is)."""
    for _ in range(rounds):
        q0 = ctx.hold_q()
        stance = Stance.of(ctx.ik, q0)
        mid_plan = mid_w + ctx.offset()
        err = float(np.hypot(*(mid_plan - stance.mid_xy)))
        if err <= tolerance_m and abs(wrap_angle(heading - stance.heading)) <= 0.05:
            return
        ctx.note(f"stance {err * 100:.0f} cm off: correcting steps")
        yield from step_to(ctx, mid_plan, heading, cfg, posture=posture, forces=forces, com_shift=com_shift,
                           name="correction")
