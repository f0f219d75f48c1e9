"""Box handling: pick a box from where it stands (a table, the floor), carry it and set it down on a
table, a platform or the floor. The carry walks in the tracker's own gait where it has one
(GoalConfig.walk_while_holding: the whole-body controller, alone or in the tracking layer; `walk_in_gait`),
else, or where the box is heavier than GoalConfig.gait_carry_max_kg or would not clear the target's top
with the gait's lower pelvis, on whole-body footsteps (`carry`).

The squeeze and the box's weight are known hand forces in the controller's dynamics; while held,
they turn with the robot's heading. A box is found by name or as the nearest one in front of the
robot; where it is comes from the scene (task knowledge) and, once moved, from where it was set
down (`ctx.box_positions`).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Generator, Iterator
from dataclasses import replace

import numpy as np

from g1_control.generator.goals.approach import (
    GAIT_PELVIS_DROP_M,
    correct_stance,
    enter_whole_body,
    stand_holding,
    step_to,
    walk_holding,
    walk_to,
)
from g1_control.generator.goals.box import (
    GRASP_DISTANCE_M,
    Approach,
    grasp_width,
    hand_forces,
    hand_points,
    place_target,
)
from g1_control.generator.goals.context import GoalContext, GoalFailed, Held
from g1_control.generator.goals.poses import PosePlanner, ReachRefused, flat_soles, stance_heading
from g1_control.generator.goals.stances import (
    ARMS_BACK,
    CLEAR_MARGIN_M,
    StanceRefused,
    box_com_shift,
    detour_poses,
    grasp_hold_poses,
    hand_height,
    pick_headings,
    place_heading,
    plan_stance,
    raised_pose,
    release_hold_poses,
    straight_poses,
)
from g1_control.generator.goals.stepping import (
    STRAIGHT_KNEE_GUARD_M,
    Footstep,
    Stance,
    SteppingConfig,
    SteppingPlan,
    stepping_trajectory,
    walk_steps,
)
from g1_control.generator.whole_body import keyframe_trajectory, smoothstep
from g1_control.rotations import wrap_angle, yaw_of
from g1_control.scene import FLOOR, Block, Box
from g1_control.types import PHASE_WHOLE_BODY, TaskGoal

RAISE_AHEAD_M = 0.10
"""Hands rise (and come back) this far ahead of the pelvis, above the box, on their way to it."""
GRAVITY = 9.81
CARRY_HANDS_Z_M = 0.80
"""A box picked low is raised, standing, until the hands are at least this high to carry it."""
JOINT_SPEED_RADPS = 1.0
PELVIS_SPEED_MPS = 0.15
"""Whole-body moves (a squat, rising with a box) go no faster than these."""


# -- planner jobs (GoalContext.compute: inline, or in the planner process) ---------------------------
def carry_plan(poses: PosePlanner, q0: np.ndarray, steps: list[Footstep], cfg: SteppingConfig, posture: np.ndarray,
               com_offset_h_m: np.ndarray, squeeze_n: float, weight_n: float, name: str = "carry") -> SteppingPlan:
    """The carry's footsteps with the box's hand forces per sample, turned with the pelvis's heading."""
    forces = hand_forces(stance_heading(flat_soles(poses.ik, q0)), squeeze_n, weight_n)
    plan = stepping_trajectory(poses.ik, q0, steps, cfg, posture=posture, hand_forces=forces,
                               com_offset_h_m=com_offset_h_m, name=name)
    traj = plan.trajectory
    traj.hand_forces_w_n = np.array([hand_forces(y, squeeze_n, weight_n) for y in traj.root_rpy_rad[:, 2]])
    return plan


def squeeze_for(ctx: GoalContext, box: Box) -> float:
    """The squeeze per hand for `box`: GoalConfig.squeeze_n, or 1.3 times the Coulomb minimum
    (m g / (2 mu) per hand) where that is more. Not more than needed: a 3 kg box squeezed with twice
    its minimum (29 N) rolled about the forward axis in the hands while held (measured)."""
    return max(ctx.config.squeeze_n, 1.3 * box.mass_kg * GRAVITY / (2.0 * box.friction))


def held_forces(ctx: GoalContext, heading: float) -> np.ndarray:
    """(2, 3) the held box's forces on the hands with the robot facing `heading` (zeros: none held)."""
    held = ctx.held
    if held is None:
        return np.zeros((2, 3))
    return hand_forces(heading, held.squeeze_n, held.box.mass_kg * GRAVITY)


def find_box(ctx: GoalContext, name: str | None) -> Box:
    if name is not None:
        box = ctx.scene.box(name)
        if box is None:
            raise GoalFailed(f"'{name}' is not a box of the scene")
        return box
    s, pos_w = ctx.world_pose()
    yaw = yaw_of(s.imu_quat_wxyz)
    fwd = np.array([math.cos(yaw), math.sin(yaw)])
    best, score = None, math.inf
    for b in ctx.scene.boxes:
        pos = ctx.box_positions.get(b.name)
        if pos is None:
            continue
        d = pos[:2] - pos_w[:2]
        dist = float(np.hypot(*d))
        if dist > 4.0 or d @ fwd < 0.3 * dist:  # in front: within ~70 degrees of the heading
            continue
        if dist < score:
            best, score = b, dist
    if best is None:
        raise GoalFailed("no box in front of the robot (within 4 m, 70 degrees of its heading)")
    return best


def support_of(ctx: GoalContext, box: Box, center_w: np.ndarray) -> Block | None:
    """What the box stands on where it is now: a table or platform whose top is under its bottom,
    else the floor (None)."""
    bottom = float(center_w[2]) - box.size[2] / 2
    for block in (*ctx.scene.tables, *ctx.scene.platforms):
        if block.contains_xy(center_w[:2]) and abs(block.height_m - bottom) < 0.05:
            return block
    return None


LIFT_CHECK_M = 0.05
"""After a pick's lift the measured hands (forward kinematics of the joints, relative to the pelvis)
are within this of the plan's, or the box did not come up: a 4.7 kg box on a 0.50 m table left the
hands 10 cm below the plan, the robot carried on with the box's weight and squeeze fed forward on
empty hands and fell on the way (bench objects seed 12, trial 7)."""


def hands_off_plan_m(ctx: GoalContext) -> float:
    """How far (vertically, relative to the pelvis) the measured hands are from the plan's now."""
    s, _ = ctx.world_pose()
    q_plan = ctx.hold_q()
    q_meas = q_plan.copy()
    q_meas[7:] = s.q_rad
    w, x, y, z = s.imu_quat_wxyz
    q_meas[3:7] = [x, y, z, w]
    return max(abs(float(ctx.poses.hand_point(q_meas, i)[2] - ctx.poses.hand_point(q_plan, i)[2])) for i in range(2))


DETOUR_STEP_S = 0.2
"""A detour's (stances.detour_poses) poses are at least this far apart in time (and no faster than
JOINT_SPEED_RADPS)."""


def _timed(q0: np.ndarray, qs: list[np.ndarray], last_s: float) -> list[tuple[float, np.ndarray]]:
    """Keyframes (time from q0's, pose) through qs: each at least DETOUR_STEP_S after the one before
    (the last at least last_s), no joint faster than JOINT_SPEED_RADPS."""
    out: list[tuple[float, np.ndarray]] = []
    t, q_prev = 0.0, q0
    for k, q in enumerate(qs):
        t += _move_s(q_prev, q, last_s if k == len(qs) - 1 else DETOUR_STEP_S)
        out.append((t, q))
        q_prev = q
    return out


def _shifted(block: Block, off_xy: np.ndarray) -> Block:
    """`block` where the robot's world frame (its odometry's drift, ctx.offset) has it."""
    return replace(block, center_xy_m=(float(block.center_xy_m[0] + off_xy[0]), float(block.center_xy_m[1] + off_xy[1])))


def _move_s(q_a: np.ndarray, q_b: np.ndarray, least_s: float) -> float:
    """A joint-space move's duration: at least least_s, and slower for big moves (a squat)."""
    return max(least_s, float(np.abs(q_b[7:] - q_a[7:]).max()) / JOINT_SPEED_RADPS,
               abs(float(q_b[2] - q_a[2])) / PELVIS_SPEED_MPS)


PLACE_GRIP_MAX_KG = 1.5
"""A pick grips for the place queued after it (place_grip_m) only a box lighter than this. Measured (`g1 bench
objects`, the layer at 250 Hz, the trials whose pick the look-ahead changed): the nine placed that were not
before weighed 0.3-1.1 kg (seeds 140-151, 163.7, 180.11, 182.3, 182.7); the four that fell weighed 1.9 and
2.2 kg (179.4, 180.4: at the pick from 0.85-0.90 m tables, the hands higher on the box; 180.4 was placed
without the look-ahead), 4.4 kg (176.10, at the pick) and 5.7 kg (143.0, in the carry's whole-body steps)."""


def place_grip_m(ctx: GoalContext, box: Box) -> float | None:
    """The hands above the box's centre (stances.hand_height) that the place queued right after this pick will
    set it down from; None: no such place, one whose height is not known before the carry, or a box of
    PLACE_GRIP_MAX_KG or more."""
    nxt = ctx.queued[0] if ctx.queued else None
    if nxt is None or nxt.kind != "place" or nxt.object not in (None, box.name) or \
            box.mass_kg >= PLACE_GRIP_MAX_KG:
        return None
    block = ctx.scene.block(nxt.target) if nxt.target not in (None, FLOOR) else None
    if block is not None:
        top = block.height_m
    elif nxt.pos_w_m is not None and nxt.target in (None, FLOOR):
        top = ctx.scene.ground_height(np.asarray(nxt.pos_w_m, dtype=float)[:2])
    else:
        return None
    return hand_height(box, top + float(box.size[2]) / 2)


def pick(ctx: GoalContext, goal: TaskGoal) -> Iterator[None]:
    cfg = ctx.config
    if ctx.held is not None:
        raise GoalFailed(f"already holding '{ctx.held.box.name}'")
    box = find_box(ctx, goal.object)
    center = ctx.box_positions.get(box.name)
    if center is None:
        raise GoalFailed(f"box '{box.name}' is held")
    _, pos_w = ctx.world_pose()
    support = support_of(ctx, box, center)
    ground = ctx.scene.ground_height(center[:2]) if support is None else 0.0
    headings = pick_headings(box, center[:2], support, pos_w[:2])
    # the stance, squat and lean for this box, before anything moves (refused here otherwise); where the place
    # queued next will want the hands higher on the box (a tall box going low), that grip first: the place
    # sets the box down from where the pick took it (Held.hand_dz_m), and from a grip at its centre the floor
    # is out of reach (refused)
    grip = place_grip_m(ctx, box)
    plan = None
    if grip is not None and grip > hand_height(box, float(center[2])) + 1e-6:
        try:
            plan = yield from ctx.compute("stance", plan_stance, box, center, support, headings, ground, cfg.lift_m,
                                          cfg.press_m, "pick it up", grip)
            ctx.note(f"pick grip: {grip * 100:.0f} cm above the box's centre, for the place queued next")
        except StanceRefused as exc:
            ctx.note(f"pick grip for the place queued next ({grip * 100:.0f} cm above the centre) refused: {exc}")
    if plan is None:
        plan = yield from ctx.compute("stance", plan_stance, box, center, support, headings, ground, cfg.lift_m,
                                      cfg.press_m, "pick it up")
    ctx.note(f"pick stance: {plan.chosen.describe()} ({plan.tried} tried)")
    approach = plan.approach
    if ctx.phase != PHASE_WHOLE_BODY:
        yield from walk_to(ctx, approach, out_m=cfg.approach_offset_m)
        yield from enter_whole_body(ctx)
    off = ctx.offset()
    yield from step_to(ctx, approach.mid_xy + off, approach.heading, cfg.steps, name="approach",
                       posture=ARMS_BACK)
    yield from correct_stance(ctx, approach.mid_xy, approach.heading, cfg.steps, posture=ARMS_BACK)
    # the grasp, from the stance the steps ended in, at the planned squat and lean
    q0 = ctx.hold_q()
    soles = flat_soles(ctx.ik, q0)
    heading = stance_heading(soles)
    floor_z = min(p[2] for p, _ in soles)
    c = center + np.append(ctx.offset(), 0.0) + np.array([0.0, 0.0, plan.hand_dz_m])
    width = grasp_width(box, heading)
    weight = box.mass_kg * GRAVITY
    squeeze = squeeze_for(ctx, box)
    mid = (soles[0][0][:2] + soles[1][0][:2]) / 2
    ahead = float((c[:2] - mid) @ np.array([math.cos(heading), math.sin(heading)]))
    lateral = np.array([-math.sin(heading), math.cos(heading)])
    left = float((c[:2] - mid) @ lateral)  # a stance off the box's line
    shift = box_com_shift(box.mass_kg, ctx.poses.mass_kg, ahead, left)
    low = plan.pelvis_z_m < ctx.poses.nominal_pelvis_m + plan.ground_z_m - 0.02 or plan.lean
    pelvis_z = floor_z + plan.pelvis_z_m - plan.ground_z_m
    nominal_z = floor_z + ctx.poses.nominal_pelvis_m
    if low:  # nothing at hand height to catch: the hands come down over the box's sides
        via = hand_points(c, heading, width, cfg.pre_gap_m + 0.03, dz_m=0.12)
    else:  # the hands rise close to the body first (a table's edge is ~0.22 m ahead of the pelvis:
        # moving them straight to the box dragged them over the table top, measured), in front of it
        # (from a stance off the box's line, the far hand's point beside the box went into the chest)
        front = c - np.append(lateral, 0.0) * (left if plan.chosen.side_m else 0.0)
        via = hand_points(front, heading, width, cfg.pre_gap_m + 0.03, dz_m=0.08, ahead_m=-(ahead - RAISE_AHEAD_M))
    pre = hand_points(c, heading, width, cfg.pre_gap_m)
    con = hand_points(c, heading, width, -cfg.press_m)
    lift = hand_points(c, heading, width, -cfg.press_m, dz_m=cfg.lift_m)
    carry_z = max(float(c[2]) + cfg.lift_m, floor_z + CARRY_HANDS_Z_M)
    rise = hand_points(np.array([c[0], c[1], carry_z]), heading, width, -cfg.press_m)
    none = np.zeros(2)
    steps = [("via", via, none, pelvis_z, plan.lean), ("pre-grasp", pre, none, pelvis_z, plan.lean),
             ("contact", con, none, pelvis_z, plan.lean), ("lift", lift, shift, pelvis_z, plan.lean)]
    if low:
        steps.append(("rise", rise, shift, nominal_z, False))
    poses = yield from ctx.compute("grasp", grasp_hold_poses, q0, soles, heading, steps, box.name,
                                   plan.chosen.describe())
    q_via, q_pre, q_con, q_lift = poses[:4]
    around: list[np.ndarray] = []
    if support is not None:  # the hands rise beside the support's top, not through it
        around = yield from ctx.compute("around", detour_poses, q0, q_via, soles, heading, none, pelvis_z,
                                        plan.lean, _shifted(support, ctx.offset()),
                                        support.height_m + 2 * CLEAR_MARGIN_M, (), True, True)
    straight: list[np.ndarray] = []
    if support is not None:  # off the box's line one arm swings across it: the hands go straight to the
        # pre-grasp points, not along the blend (its hand dipped under the table's top); on the line only where
        # the blend takes a hand into the support's top (stances.straight_poses)
        block = None if plan.chosen.side_m else _shifted(support, ctx.offset())
        straight = yield from ctx.compute("straight", straight_poses, q_via, q_pre, soles, heading, none, pelvis_z,
                                          plan.lean, block)
        if straight and block is not None:
            ctx.note(f"the hands go straight to the pre-grasp points: the blend takes one into the top of "
                     f"'{support.name}'")
    path = _timed(q0, [*around, q_via], 1.2)
    t = {"via": path[-1][0]}
    if straight and not plan.chosen.side_m:  # timed by joint speed (a wrist's turn: straight_poses)
        across = [(t["via"] + dt, q) for dt, q in _timed(q_via, [*straight, q_pre], 1.0)]
        t["pre"] = across.pop()[0]
    else:
        t["pre"] = t["via"] + 1.0 + 0.5 * bool(straight)
        across = [(t["via"] + (k + 1) / (len(straight) + 1) * (t["pre"] - t["via"]), q)
                  for k, q in enumerate(straight)]
    t["con"] = t["pre"] + 0.8
    t["squeeze"] = t["con"] + 0.5
    t["lift"] = t["squeeze"] + 1.2
    keys = [(0.0, q0), *path, *across, (t["pre"], q_pre), (t["con"], q_con), (t["squeeze"], q_con),
            (t["lift"], q_lift)]
    if low:
        t["rise"] = t["lift"] + _move_s(q_lift, poses[4], 1.2)
        keys.append((t["rise"], poses[4]))
    t["end"] = keys[-1][0] + 1.0
    keys.append((t["end"], keys[-1][1]))
    full = hand_forces(heading, squeeze, weight)
    squeeze_only = hand_forces(heading, squeeze, 0.0)

    def forces(tk: float) -> np.ndarray:
        a = float(smoothstep((tk - t["con"] + 0.1) / (t["squeeze"] - t["con"] + 0.1)))
        b = float(smoothstep((tk - t["squeeze"]) / cfg.force_ramp_s))
        return a * squeeze_only + b * (full - squeeze_only)

    ctx.info.update(box=box.name, box_start_w_m=center.tolist(), lift_m=cfg.lift_m,
                    held_from_s=ctx.t + t["lift"], stance=plan.chosen.describe())
    yield from ctx.run(keyframe_trajectory("pick", keys, hand_forces=forces))
    lag = hands_off_plan_m(ctx)
    if lag > LIFT_CHECK_M:  # the box did not come up: set it back down, open the hands, stand as before
        back = [(0.0, ctx.hold_q()), (1.2, q_con), (2.0, q_pre), (2.8, q_via)]
        back.append((2.8 + _move_s(q_via, q0, 1.2), q0))

        def letting_go(tk: float) -> np.ndarray:
            b = 1.0 - float(smoothstep(tk / 1.2))
            a = 1.0 - float(smoothstep((tk - 1.2) / 0.8))
            return a * squeeze_only + b * (full - squeeze_only)

        ctx.info["released_s"] = ctx.t  # set down on purpose from here (g1 bench objects: not a drop)
        yield from ctx.run(keyframe_trajectory("let go", back, hand_forces=letting_go))
        raise GoalFailed(f"box '{box.name}' ({box.mass_kg:.1f} kg) did not come up with the hands: after the lift "
                         f"they were {lag * 100:.0f} cm off the plan; set back down, the hands opened")
    ctx.held = Held(box, full, squeeze, heading_rad=heading, hand_dz_m=plan.hand_dz_m)
    ctx.box_positions[box.name] = None


def place(ctx: GoalContext, goal: TaskGoal) -> Iterator[None]:
    """Set the held box down (carrying it there first when the place is away from the stance). Off a
    platform the executor then hands back to the walking policy."""
    cfg = ctx.config
    if ctx.held is None:
        raise GoalFailed("holding no box")
    held = ctx.held
    box = held.box
    if goal.object is not None and goal.object != box.name:
        raise GoalFailed(f"holding '{box.name}', not '{goal.object}'")
    s, pos_w = ctx.world_pose()
    target, point = goal.target, goal.pos_w_m
    if target is not None and ctx.scene.block(target) is None and point is not None:
        target = None  # a place the scene does not have as a table or platform: its point
    if target is None and point is None:  # "put it down in front": a table there, else the floor
        yaw = yaw_of(s.imu_quat_wxyz)
        ahead = pos_w[:2] + GRASP_DISTANCE_M * np.array([math.cos(yaw), math.sin(yaw)])
        near = [b for b in (*ctx.scene.tables, *ctx.scene.platforms) if b.distance_xy(ahead) < 0.35]
        if near:
            target = min(near, key=lambda b: b.distance_xy(ahead)).name
        else:
            point = np.array([ahead[0], ahead[1], box.size[2] / 2])
    support = ctx.scene.block(target) if target is not None and target != FLOOR else None
    if target is not None and target != FLOOR and support is None:
        raise ReachRefused(f"'{target}' is not a table or platform of the scene")
    if point is not None:
        top = support.height_m if support is not None else ctx.scene.ground_height(np.asarray(point[:2]))
        center_w = np.array([point[0], point[1], top + box.size[2] / 2])
    else:
        center_w, _ = place_target(ctx.scene, box, target, None, pos_w[:2])
    heading_now = yaw_of(s.imu_quat_wxyz)
    heading = place_heading(support, center_w[:2], pos_w[:2])
    # the box turns with the robot: as held, its faces across the new heading are the ones in the hands
    as_held = replace(box, yaw_rad=box.yaw_rad + wrap_angle(heading - held.heading_rad))
    ground = 0.0 if support is not None else ctx.scene.ground_height(center_w[:2])
    # the hands where the pick took the box (Held.hand_dz_m), not where a pick at the place would: a tall box
    # taken at its centre from a table and planned as gripped high for the floor was let go 11 cm up and
    # fell over (`g1 bench objects` 163.7, traced)
    plan = yield from ctx.compute("stance", plan_stance, as_held, center_w, support, [heading], ground, None,
                                  cfg.press_m, "set it down there", held.hand_dz_m)
    ctx.note(f"place stance: {plan.chosen.describe()} ({plan.tried} tried; heading now {heading_now:.2f})")
    approach = plan.approach
    ctx.info.update(box=box.name, target_w_m=center_w.tolist(), stance=plan.chosen.describe())
    q0 = ctx.hold_q()
    posture = q0[7:].copy()
    weight = box.mass_kg * GRAVITY
    squeeze = held.squeeze_n
    stance = Stance.of(ctx.ik, q0)
    carry_shift = box_com_shift(box.mass_kg, ctx.poses.mass_kg, GRASP_DISTANCE_M)
    far = float(np.hypot(*(approach.mid_xy - stance.mid_xy))) > 0.05 or \
        abs(wrap_angle(approach.heading - stance.heading)) > 0.05
    level = ctx.on_platform is None and abs(ctx.scene.ground_height(approach.mid_xy) - ctx.scene.ground_height(
        stance.mid_xy - ctx.offset())) < 0.01  # no step up or down on the way (whole-body steps take those)
    gait = far and cfg.walk_while_holding and level
    if gait and box.mass_kg > cfg.gait_carry_max_kg:
        gait = False
        ctx.note(f"carry in whole-body steps: the box's {box.mass_kg:.1f} kg is more than the gait carries "
                 f"({cfg.gait_carry_max_kg:.1f} kg)")
    if gait:  # the tracker's own gait walks it there (walk_in_gait), where it can
        walked = yield from walk_in_gait(ctx, approach, posture, weight, carry_shift, support)
        if walked is not None:
            posture, step_cfg = walked
            yield from correct_stance(ctx, approach.mid_xy, approach.heading, step_cfg, posture=posture,
                                      forces=hand_forces(approach.heading, squeeze, weight),
                                      com_shift=ctx.poses.com_offset_m + carry_shift)
            far = False
        else:
            posture = ctx.hold_q()[7:].copy()
    if far and support is not None:  # the box carried clear above the support's top, not into its side
        yield from raise_over(ctx, support, posture, carry_shift)
        posture = ctx.hold_q()[7:].copy()
    if far:
        off = ctx.offset()
        # carry: the hand forces turn with the robot, so plan them per heading: held constant in
        # the robot's frame (the squeeze across it, the weight down)
        # (a carry over a table may walk taller or raise the box further: the corrections do the same)
        posture, step_cfg = yield from carry(ctx, approach.mid_xy + off, approach.heading, posture, weight,
                                             carry_shift, over=support)
        yield from correct_stance(ctx, approach.mid_xy, approach.heading, step_cfg, posture=posture,
                                  forces=hand_forces(approach.heading, squeeze, weight),
                                  com_shift=ctx.poses.com_offset_m + carry_shift)
    q0 = ctx.hold_q()
    soles = flat_soles(ctx.ik, q0)
    heading = stance_heading(soles)
    floor_z = min(p[2] for p, _ in soles)
    c = center_w + np.append(ctx.offset(), 0.0) + np.array([0.0, 0.0, plan.hand_dz_m])
    width = grasp_width(replace(box, yaw_rad=box.yaw_rad + wrap_angle(heading - held.heading_rad)), heading)
    mid = (soles[0][0][:2] + soles[1][0][:2]) / 2
    held_ahead = float((c[:2] - mid) @ np.array([math.cos(heading), math.sin(heading)]))
    shift = box_com_shift(box.mass_kg, ctx.poses.mass_kg, held_ahead)
    low = plan.pelvis_z_m < ctx.poses.nominal_pelvis_m + plan.ground_z_m - 0.02 or plan.lean
    pelvis_z = floor_z + plan.pelvis_z_m - plan.ground_z_m
    above = hand_points(c, heading, width, -cfg.press_m, dz_m=0.10)
    down = hand_points(c, heading, width, -cfg.press_m, dz_m=0.005)
    opened = hand_points(c, heading, width, cfg.pre_gap_m, dz_m=0.005)
    if low:
        out = hand_points(c, heading, width, cfg.pre_gap_m + 0.03, dz_m=0.12)
    else:
        out = hand_points(c, heading, width, cfg.pre_gap_m + 0.03, dz_m=0.08, ahead_m=-(held_ahead - RAISE_AHEAD_M))
    q_above, q_down, q_open, q_out, q_stand = yield from ctx.compute(
        "release", release_hold_poses, q0, soles, heading, (above, down, opened, out), shift, pelvis_z, plan.lean,
        low, plan.chosen.describe())
    over: list[np.ndarray] = []
    back: list[np.ndarray] = []
    if support is not None:  # the box goes over the support's edge, the hands come back beside it
        block = _shifted(support, ctx.offset())
        depth = grasp_width(replace(box, yaw_rad=box.yaw_rad + wrap_angle(heading - held.heading_rad)),
                            heading + math.pi / 2)
        under = plan.hand_dz_m + box.size[2] / 2
        probes = ((depth / 2, under), (-depth / 2, under), (0.0, under))
        over = yield from ctx.compute("over", detour_poses, q0, q_down, soles, heading, shift, pelvis_z, plan.lean,
                                      block, support.height_m + under + 2 * CLEAR_MARGIN_M, probes, True, True)
        back = yield from ctx.compute("back", detour_poses, q_out, q_stand, soles, heading, np.zeros(2), pelvis_z,
                                      plan.lean, block, support.height_m + 2 * CLEAR_MARGIN_M)
    t = {"above": _move_s(q0, q_above, 0.0) if low else 0.0}
    if over:
        t["down"] = _timed(q0, [*over, q_down], 1.5)[-1][0]
        t["above"] = t["down"] - 1.5
    else:
        t["down"] = t["above"] + 1.5
    t["release"] = t["down"] + 0.7
    t["open"] = t["release"] + 0.8
    t["out"] = t["open"] + 1.0
    retreat = [(t["out"] + dt, q) for dt, q in _timed(q_out, [*back, q_stand], 1.5)]
    t["stand"] = retreat[-1][0]
    t["end"] = t["stand"] + 0.5
    full = hand_forces(heading, squeeze, weight)
    squeeze_only = hand_forces(heading, squeeze, 0.0)

    def forces(tk: float) -> np.ndarray:
        b = 1.0 - float(smoothstep((tk - t["down"] + cfg.force_ramp_s) / cfg.force_ramp_s))
        a = 1.0 - float(smoothstep((tk - t["down"]) / (t["release"] - t["down"])))
        return a * squeeze_only + b * (full - squeeze_only)

    if over:
        down_keys = _timed(q0, [*over, q_down], 1.5)
    else:
        down_keys = ([(t["above"], q_above)] if low else []) + [(t["down"], q_down)]
    keys = [(0.0, q0), *down_keys, (t["release"], q_down), (t["open"], q_open), (t["out"], q_out), *retreat,
            (t["end"], q_stand)]
    yield from ctx.run(keyframe_trajectory("place", keys, hand_forces=forces))
    ctx.info["released_s"] = ctx.t - t["end"] + t["release"]
    ctx.held = None
    ctx.box_positions[box.name] = center_w


BOX_OVER_TOP_M = 0.08
"""A box carried to a support goes with its bottom at least this far above the support's top."""


def raise_over(ctx: GoalContext, support: Block, posture: np.ndarray, carry_shift: np.ndarray) -> Iterator[None]:
    """Before carrying the held box to `support`: raise it (standing still) until its bottom is
    BOX_OVER_TOP_M above the top, else refuse (the box stays held). Carried at the pick's height, the
    box came into a 0.90 m table's side on the last steps of the carry and the robot fell (bench
    objects seed 7, trial 0)."""
    q0 = ctx.hold_q()
    hands_z = min(float(ctx.poses.hand_point(q0, i)[2]) for i in range(2))
    need = hands_over_m(ctx, support)
    if hands_z >= need:
        return
    yield from _raise_by(ctx, support, need - hands_z, carry_shift, need)


def hands_over_m(ctx: GoalContext, support: Block) -> float:
    """How high the hand points go for the held box's bottom to be BOX_OVER_TOP_M over `support`."""
    held = ctx.held
    assert held is not None
    return support.height_m + BOX_OVER_TOP_M + held.hand_dz_m + held.box.size[2] / 2


def hands_sag_m(ctx: GoalContext) -> float:
    """How far the measured hands sit below the reference's now (mean of the two; negative: above),
    each over its own soles: the joint angles and the IMU's tilt, robot-side knowledge (the held
    box's weight bends the arms and the body under the tracker)."""
    s = ctx.state
    assert s is not None
    q_plan = ctx.hold_q()
    q_meas = q_plan.copy()
    q_meas[7:] = s.q_rad
    w, x, y, z = s.imu_quat_wxyz
    q_meas[3:7] = [x, y, z, w]

    def over_soles(q: np.ndarray) -> float:
        floor = min(float(p[2]) for p, _ in flat_soles(ctx.ik, q))
        return float(np.mean([ctx.poses.hand_point(q, i)[2] for i in range(2)])) - floor

    return over_soles(q_plan) - over_soles(q_meas)


def lowest_hands_m(poses: PosePlanner, traj, every_s: float = 0.1) -> float:
    """The lowest hand point along a whole-body trajectory (sampled every `every_s`)."""
    low = math.inf
    for tk in np.arange(0.0, traj.duration_s + 1e-9, every_s):
        j = traj.sample(float(tk))
        w, x, y, z = j.root_quat_wxyz
        q = np.concatenate([j.root_pos_w_m, [x, y, z, w], j.q_rad])
        low = min(low, *(float(poses.hand_point(q, i)[2]) for i in range(2)))
    return low


def _raise_by(ctx: GoalContext, support: Block, dz_m: float, carry_shift: np.ndarray, need: float,
              strict: bool = True, accept: Callable[[np.ndarray], bool] | None = None) -> Generator[None, None, bool]:
    """Raise the held box's hands dz_m (standing still), else refuse (the box stays held); not
    `strict`: as far as they go (refused only for the CoM); accept: not at all (False, nothing moved)
    where it says no to the raised pose. True: raised."""
    held = ctx.held
    assert held is not None
    q0 = ctx.hold_q()
    soles = flat_soles(ctx.ik, q0)
    heading = stance_heading(soles)
    up = yield from ctx.compute("raise", raised_pose, q0, soles, heading, dz_m, carry_shift, float(q0[2]))
    if accept is not None and (up.com_error_m > 0.03 or not accept(up.q)):
        return False
    if (strict and up.residual_m > 0.03) or up.com_error_m > 0.03:
        raise GoalFailed(f"box '{held.box.name}' cannot be held above '{support.name}' ({support.height_m:.2f} m): "
                         f"the hands get only within {up.residual_m * 100:.1f} cm of {need:.2f} m up "
                         f"(CoM {up.com_error_m * 100:.1f} cm off)")
    q_up = up.q
    forces = held_forces(ctx, heading)
    move = _move_s(q0, q_up, 1.5)
    yield from ctx.run(keyframe_trajectory("raise", [(0.0, q0), (move, q_up), (move + 0.5, q_up)],
                                           hand_forces=lambda _t: forces))
    return True


CARRY_CLEAR_M = 0.03
"""A box carried to a table (GoalConfig.carry_over_check) goes with its bottom at least this far over
the top along the whole carry's plan, less the measured sag of the hands, else the place refuses
before walking (the box stays held). A box 0.5-1 cm over a 0.92 m table dragged on it and the robot
fell (bench objects seed 19, trial 8); BOX_OVER_TOP_M is what is asked, this is what is accepted."""


def gait_hands_m(ctx: GoalContext, q: np.ndarray) -> float:
    """The lower hand point walking in the tracker's own gait with the waist and arms held as in q: the
    pelvis level (the gait holds it so; a stand may pitch it, and the hands then sit ~5 cm higher than
    they walk, measured on a floor pick's stand) at the gait's height over q's soles (GAIT_PELVIS_DROP_M
    below the nominal stand)."""
    floor = min(float(p[2]) for p, _ in flat_soles(ctx.ik, q))
    level = q.copy()
    yaw = yaw_of(np.array([q[6], q[3], q[4], q[5]]))
    level[3:7] = [0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2)]
    hands = min(float(ctx.poses.hand_point(level, i)[2]) for i in range(2))
    return hands - float(q[2]) + floor + ctx.poses.nominal_pelvis_m - GAIT_PELVIS_DROP_M


def walk_in_gait(ctx: GoalContext, approach: Approach, posture: np.ndarray, weight: float, com_shift: np.ndarray,
                 over: Block | None) -> Generator[None, None, tuple[np.ndarray, SteppingConfig] | None]:
    """Carry the held box to `approach` in the tracker's own gait (GoalConfig.walk_while_holding: the
    whole-body controller): raised first, standing, until its bottom passes BOX_OVER_TOP_M over `over`'s
    top with the gait's lower pelvis (GAIT_PELVIS_DROP_M below the nominal stand, the arms held as they
    are, less the measured sag); then back off, turn, walk straight, turn (approach.walk_holding, the
    box's forces on the hands turned with the heading by the executor's holding reference), stand holding
    it, and the last steps into the stance in whole-body steps (carry, with its own check over the top).
    Returns the posture and the stepping settings, as carry does; None, before walking, where the bottom
    would pass less than CARRY_CLEAR_M over the top in the gait (the raise is planned first and made only
    where its pose clears it): whole-body steps may walk taller (carry keeps the raise's pelvis), the
    caller carries in them."""
    cfg = ctx.config
    if over is not None and ctx.held is not None and cfg.carry_over_check:
        need = hands_over_m(ctx, over)
        sag = max(0.0, hands_sag_m(ctx))
        low = gait_hands_m(ctx, ctx.hold_q()) - sag
        if low < need - 0.005:  # raised, where the pose found clears the top in the gait (planned, then moved)
            clears = lambda q: gait_hands_m(ctx, q) - sag - (need - BOX_OVER_TOP_M) >= CARRY_CLEAR_M
            if (yield from _raise_by(ctx, over, need - low, com_shift, need, strict=False, accept=clears)):
                posture = ctx.hold_q()[7:].copy()
                was, low = low, gait_hands_m(ctx, ctx.hold_q()) - sag
                ctx.note(f"carry over '{over.name}' in the gait: the hands {was:.3f} m -> {low:.3f} m "
                         f"({need:.3f} m asked)")
        clear = low - (need - BOX_OVER_TOP_M)
        if clear < CARRY_CLEAR_M:
            ctx.note(f"carry over '{over.name}': in the gait the box's bottom would pass {clear * 100:.1f} cm over "
                     f"the top (at least {CARRY_CLEAR_M * 100:.0f} cm): whole-body steps")
            return None
    yield from walk_holding(ctx, approach, posture, out_m=cfg.approach_offset_m, back_m=cfg.backup_m)
    yield from stand_holding(ctx, com_shift, lambda heading: held_forces(ctx, heading))
    posture = ctx.hold_q()[7:].copy()
    return (yield from carry(ctx, approach.mid_xy + ctx.offset(), approach.heading, posture, weight, com_shift,
                             over=over, back_m=0.0, name="carry in"))


def carry(ctx: GoalContext, mid_xy: np.ndarray, heading: float, posture: np.ndarray, weight: float,
          com_shift: np.ndarray, over: Block | None = None, back_m: float | None = None, name: str = "carry"
          ) -> Generator[None, None, tuple[np.ndarray, SteppingConfig]]:
    """Footsteps to a stance with the box held: back up from the table, turn, walk, turn; the
    hand forces follow the robot's heading along the way.

    Carried to a table (`over`, with GoalConfig.carry_over_check): the plan's lowest hand points
    less the measured sag (hands_sag_m) must hold the box's bottom BOX_OVER_TOP_M over the top
    (hands_over_m). Short of that (the carry walks with the pelvis at SteppingConfig
    pelvis_above_ground_m, 2 cm below the stand the box was raised in, and the raise may end up to
    3 cm short at the arms' reach), the carry is planned again with the pelvis kept where the raise
    left it (no higher than the nominal stand + STRAIGHT_KNEE_GUARD_M); still short, the box is raised
    as far as the arms go, standing, and planned once more; still less than CARRY_CLEAR_M over the
    top, the place refuses. Returns the upper-body posture and the stepping settings carried with
    (the corrections after the carry use the same). back_m: how far it backs up first (None:
    GoalConfig.backup_m); name: the plan's stage name."""
    cfg = ctx.config
    step_cfg = cfg.carry
    back = cfg.backup_m if back_m is None else back_m
    plan = yield from _carry_plan(ctx, mid_xy, heading, posture, com_shift, step_cfg, back, name)
    if plan is None:  # there already
        return posture, step_cfg
    if over is not None and ctx.held is not None and cfg.carry_over_check:
        need = hands_over_m(ctx, over)
        sag = max(0.0, hands_sag_m(ctx))
        low = (yield from ctx.compute("carry check", lowest_hands_m, plan.trajectory)) - sag
        for attempt in ("pelvis", "raise"):
            if low >= need - 0.005:
                break
            if attempt == "raise":
                yield from _raise_by(ctx, over, need - low, com_shift, need, strict=False)
                posture = ctx.hold_q()[7:].copy()
            q0 = ctx.hold_q()
            floor = min(float(p[2]) for p, _ in flat_soles(ctx.ik, q0))
            kept = min(float(q0[2]) - floor, ctx.poses.nominal_pelvis_m + STRAIGHT_KNEE_GUARD_M)
            step_cfg = replace(cfg.carry, pelvis_above_ground_m=max(cfg.carry.pelvis_above_ground_m, kept))
            plan = yield from _carry_plan(ctx, mid_xy, heading, posture, com_shift, step_cfg, back, name)
            assert plan is not None
            was, low = low, (yield from ctx.compute("carry check", lowest_hands_m, plan.trajectory)) - sag
            ctx.note(f"carry over '{over.name}': the hands {was:.3f} m -> {low:.3f} m ({attempt}; "
                     f"{need:.3f} m asked, sag {sag * 100:.1f} cm)")
        clear = low - (need - BOX_OVER_TOP_M)
        if clear < CARRY_CLEAR_M:
            raise GoalFailed(f"box '{ctx.held.box.name}' cannot be carried over '{over.name}' "
                             f"({over.height_m:.2f} m): its bottom would pass {clear * 100:.1f} cm over the top "
                             f"(at least {CARRY_CLEAR_M * 100:.0f} cm; the hands sag {sag * 100:.1f} cm)")
    ctx.last_steps = plan
    yield from ctx.run(plan.trajectory)
    return posture, step_cfg


def _carry_plan(ctx: GoalContext, mid_xy: np.ndarray, heading: float, posture: np.ndarray,
                com_shift: np.ndarray, step_cfg: SteppingConfig, back_m: float, name: str
                ) -> Generator[None, None, SteppingPlan | None]:
    q0 = ctx.hold_q()
    stance = Stance.of(ctx.ik, q0)
    ground = ctx.scene.ground_height
    steps: list[Footstep] = []
    if back_m > 0:
        back = stance.mid_xy - back_m * np.array([math.cos(stance.heading), math.sin(stance.heading)])
        steps = walk_steps(stance, back, stance.heading, step_cfg, lambda xy: ground(xy), backward_max_m=1.0)
        for st in steps:
            stance = stance.apply(st)
    steps += walk_steps(stance, mid_xy, heading, step_cfg, lambda xy: ground(xy), then=steps)
    if not steps:
        return None
    held = ctx.held  # the box's squeeze (squeeze_for) and weight on the hands; none held: no forces
    squeeze, load = (held.squeeze_n, held.box.mass_kg * GRAVITY) if held is not None else (0.0, 0.0)
    plan = yield from ctx.compute(name, carry_plan, q0, steps, step_cfg, posture, ctx.poses.com_offset_m + com_shift,
                                  squeeze, load, name)
    ctx.last_steps = plan
    if plan.sole_error_m > 0.03:
        raise GoalFailed(f"{name}: the footsteps are out of the legs' reach (plan off by "
                         f"{plan.sole_error_m * 100:.0f} cm)")
    return plan
