"""Box handling: pick a box from where it stands (a table, the floor), carry it on the whole-body
controller's own footsteps and set it down on a table, a platform or the floor.

The squeeze and the box's weight are known hand forces in the controller's dynamics; while held,
they turn with the robot's heading. A box is found by name or as the nearest one in front of the
robot; where it is comes from the scene (task knowledge) and, once moved, from where it was set
down (`ctx.box_positions`).
"""

from __future__ import annotations

import math
from collections.abc import Iterator

import numpy as np

from g1_control.generator.goals.approach import correct_stance, enter_whole_body, step_to, walk_to
from g1_control.generator.goals.box import (
    GRASP_DISTANCE_M,
    grasp_width,
    hand_forces,
    hand_points,
    pick_approach,
    place_target,
)
from g1_control.generator.goals.context import GoalContext, GoalFailed, Held
from g1_control.generator.goals.poses import PosePlanner, ReachRefused, Sole, flat_soles, stance_heading
from g1_control.generator.goals.stepping import (
    Footstep,
    Stance,
    SteppingConfig,
    SteppingPlan,
    stepping_trajectory,
    walk_steps,
)
from g1_control.generator.whole_body import keyframe_trajectory, smoothstep
from g1_control.robot import g1
from g1_control.rotations import wrap_angle, yaw_of
from g1_control.scene import Box
from g1_control.types import PHASE_WHOLE_BODY, TaskGoal

ARMS_BACK = g1.DEFAULT_Q_RAD.copy()
"""Stepping up to a table: the arms swung back (hand points ~5 cm ahead of the pelvis instead of
17 cm at table height), so the hands cannot catch the table's edge (it threw the robot over,
measured)."""
for _side in ("left", "right"):
    ARMS_BACK[g1.JOINT_INDEX[f"{_side}_shoulder_pitch_joint"]] = 0.6
    ARMS_BACK[g1.JOINT_INDEX[f"{_side}_elbow_joint"]] = 0.4
RAISE_AHEAD_M = 0.10
"""Hands rise (and come back) this far ahead of the pelvis, above the box, on their way to it."""
GRAVITY = 9.81
HandPoints = tuple[np.ndarray, np.ndarray]
"""Left and right hand-frame points (box.hand_points)."""


# -- planner jobs (GoalContext.compute: inline, or in the planner process) ---------------------------
def grasp_poses(poses: PosePlanner, q0: np.ndarray, soles: list[Sole], heading: float,
                points: tuple[HandPoints, HandPoints, HandPoints, HandPoints], lift_shift: np.ndarray,
                box_name: str) -> list[np.ndarray]:
    """The via, pre-grasp, contact and lift poses (each from the one before), the CoM shifted by
    `lift_shift` for the lift; ReachRefused when the hands cannot get within 3 cm of a point."""
    out = []
    q = q0
    for name, targets, com_shift in zip(("via", "pre-grasp", "contact", "lift"), points,
                                        (None, None, None, lift_shift)):
        res = poses.hands_on(q, soles, targets, heading, com_shift)
        if res.residual_m > 0.01:  # a poor warm start (the pose before): again from the stance
            again = poses.hands_on(q0, soles, targets, heading, com_shift)
            res = again if again.residual_m < res.residual_m else res
        if res.residual_m > 0.03 and name != "via":
            raise ReachRefused(f"box '{box_name}': the hands get only within {res.residual_m * 100:.1f} cm "
                               f"of the {name} points (out of reach)")
        q = res.q
        out.append(q)
    return out


def release_poses(poses: PosePlanner, q0: np.ndarray, soles: list[Sole], heading: float,
                  points: tuple[HandPoints, HandPoints, HandPoints], shift: np.ndarray):
    """The box set down, the hands opened, the hands out, standing: (PoseResult, q, q, q)."""
    down, opened, out = points
    down_pose = poses.hands_on(q0, soles, down, heading, shift)
    if down_pose.residual_m > 0.03:
        raise ReachRefused(f"the hands get only within {down_pose.residual_m * 100:.1f} cm of where the box "
                           "goes (out of reach)")
    q_open = poses.hands_on(down_pose.q, soles, opened, heading).q
    q_out = poses.hands_on(q_open, soles, out, heading).q
    ground = min(p[2] for p, _ in soles)
    return down_pose, q_open, q_out, poses.stand(q_out, soles, ground + poses.nominal_pelvis_m, g1.DEFAULT_Q_RAD)


def carry_plan(poses: PosePlanner, q0: np.ndarray, steps: list[Footstep], cfg: SteppingConfig, posture: np.ndarray,
               com_offset_h_m: np.ndarray, squeeze_n: float, weight_n: float) -> SteppingPlan:
    """The carry's footsteps with the box's hand forces per sample, turned with the pelvis's heading."""
    forces = hand_forces(stance_heading(flat_soles(poses.ik, q0)), squeeze_n, weight_n)
    plan = stepping_trajectory(poses.ik, q0, steps, cfg, posture=posture, hand_forces=forces,
                               com_offset_h_m=com_offset_h_m, name="carry")
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


def pick(ctx: GoalContext, goal: TaskGoal) -> Iterator[None]:
    cfg = ctx.config
    if ctx.held is not None:
        raise GoalFailed(f"already holding '{ctx.held.box.name}'")
    box = find_box(ctx, goal.object)
    center = ctx.box_positions.get(box.name)
    if center is None:
        raise GoalFailed(f"box '{box.name}' is held")
    _, pos_w = ctx.world_pose()
    approach = pick_approach(ctx.scene, box, center[:2], pos_w[:2])
    if ctx.phase != PHASE_WHOLE_BODY:
        yield from walk_to(ctx, approach, out_m=cfg.approach_offset_m)
        yield from enter_whole_body(ctx)
    off = ctx.offset()
    yield from step_to(ctx, approach.mid_xy + off, approach.heading, cfg.steps, name="approach",
                       posture=ARMS_BACK)
    yield from correct_stance(ctx, approach.mid_xy, approach.heading, cfg.steps, posture=ARMS_BACK)
    # the grasp, from the stance the steps ended in
    q0 = ctx.hold_q()
    soles = flat_soles(ctx.ik, q0)
    heading = stance_heading(soles)
    c = center + np.append(ctx.offset(), 0.0)
    width = grasp_width(box, heading)
    weight = box.mass_kg * GRAVITY
    squeeze = squeeze_for(ctx, box)
    # the hands rise close to the body first (a table's edge is ~0.22 m ahead of the pelvis:
    # moving them straight to the box dragged them over the table top, measured)
    via = hand_points(c, heading, width, cfg.pre_gap_m + 0.03, dz_m=0.08, ahead_m=-(GRASP_DISTANCE_M - RAISE_AHEAD_M))
    pre = hand_points(c, heading, width, cfg.pre_gap_m)
    con = hand_points(c, heading, width, -cfg.press_m)
    lift = hand_points(c, heading, width, -cfg.press_m, dz_m=cfg.lift_m)
    shift = np.array([-box.mass_kg / ctx.poses.mass_kg * GRASP_DISTANCE_M, 0.0])
    q_via, q_pre, q_con, q_lift = yield from ctx.compute("grasp", grasp_poses, q0, soles, heading,
                                                         (via, pre, con, lift), shift, box.name)
    t = {"via": 1.2, "pre": 2.2, "con": 3.0, "squeeze": 3.5, "lift": 4.7, "end": 5.7}
    full = hand_forces(heading, squeeze, weight)
    squeeze_only = hand_forces(heading, squeeze, 0.0)

    def forces(tk: float) -> np.ndarray:
        a = float(smoothstep((tk - t["con"] + 0.1) / (t["squeeze"] - t["con"] + 0.1)))
        b = float(smoothstep((tk - t["squeeze"]) / cfg.force_ramp_s))
        return a * squeeze_only + b * (full - squeeze_only)

    keys = [(0.0, q0), (t["via"], q_via), (t["pre"], q_pre), (t["con"], q_con), (t["squeeze"], q_con),
            (t["lift"], q_lift), (t["end"], q_lift)]
    ctx.info.update(box=box.name, box_start_w_m=center.tolist(), lift_m=cfg.lift_m,
                    held_from_s=ctx.t + t["lift"])
    yield from ctx.run(keyframe_trajectory("pick", keys, hand_forces=forces))
    ctx.held = Held(box, full, squeeze)
    ctx.box_positions[box.name] = None


def place(ctx: GoalContext, goal: TaskGoal) -> Iterator[None]:
    """Set the held box down (carrying it there first when the place is away from the stance). Off a
    platform the executor then hands back to the walking policy."""
    cfg = ctx.config
    if ctx.held is None:
        raise GoalFailed("holding no box")
    box = ctx.held.box
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
    center_w, approach = place_target(ctx.scene, box, target, point, pos_w[:2])
    ctx.info.update(box=box.name, target_w_m=center_w.tolist())
    q0 = ctx.hold_q()
    posture = q0[7:].copy()
    weight = box.mass_kg * GRAVITY
    squeeze = ctx.held.squeeze_n
    shift = np.array([-box.mass_kg / ctx.poses.mass_kg * GRASP_DISTANCE_M, 0.0])
    stance = Stance.of(ctx.ik, q0)
    far = float(np.hypot(*(approach.mid_xy - stance.mid_xy))) > 0.05 or \
        abs(wrap_angle(approach.heading - stance.heading)) > 0.05
    if far:
        off = ctx.offset()
        # carry: the hand forces turn with the robot, so plan them per heading: held constant in
        # the robot's frame (the squeeze across it, the weight down)
        yield from carry(ctx, approach.mid_xy + off, approach.heading, posture, weight, shift)
        yield from correct_stance(ctx, approach.mid_xy, approach.heading, cfg.carry, posture=posture,
                              forces=hand_forces(approach.heading, squeeze, weight),
                              com_shift=ctx.poses.com_offset_m + shift)
    q0 = ctx.hold_q()
    soles = flat_soles(ctx.ik, q0)
    heading = stance_heading(soles)
    c = center_w + np.append(ctx.offset(), 0.0)
    width = grasp_width(box, heading)
    down = hand_points(c, heading, width, -cfg.press_m, dz_m=0.005)
    opened = hand_points(c, heading, width, cfg.pre_gap_m, dz_m=0.005)
    out = hand_points(c, heading, width, cfg.pre_gap_m + 0.03, dz_m=0.08, ahead_m=-(GRASP_DISTANCE_M - RAISE_AHEAD_M))
    q_down, q_open, q_out, q_stand = yield from ctx.compute("release", release_poses, q0, soles, heading,
                                                            (down, opened, out), shift)
    t = {"down": 1.5, "release": 2.2, "open": 3.0, "out": 4.0, "stand": 5.5, "end": 6.0}
    full = hand_forces(heading, squeeze, weight)
    squeeze_only = hand_forces(heading, squeeze, 0.0)

    def forces(tk: float) -> np.ndarray:
        b = 1.0 - float(smoothstep((tk - t["down"] + cfg.force_ramp_s) / cfg.force_ramp_s))
        a = 1.0 - float(smoothstep((tk - t["down"]) / (t["release"] - t["down"])))
        return a * squeeze_only + b * (full - squeeze_only)

    keys = [(0.0, q0), (t["down"], q_down.q), (t["release"], q_down.q), (t["open"], q_open), (t["out"], q_out),
            (t["stand"], q_stand), (t["end"], q_stand)]
    yield from ctx.run(keyframe_trajectory("place", keys, hand_forces=forces))
    ctx.info["released_s"] = ctx.t - t["end"] + t["release"]
    ctx.held = None
    ctx.box_positions[box.name] = center_w


def carry(ctx: GoalContext, mid_xy: np.ndarray, heading: float, posture: np.ndarray, weight: float,
          com_shift: np.ndarray) -> Iterator[None]:
    """Footsteps to a stance with the box held: back up from the table, turn, walk, turn; the
    hand forces follow the robot's heading along the way."""
    cfg = ctx.config
    q0 = ctx.hold_q()
    stance = Stance.of(ctx.ik, q0)
    back = stance.mid_xy - cfg.backup_m * np.array([math.cos(stance.heading), math.sin(stance.heading)])
    ground = ctx.scene.ground_height
    steps = walk_steps(stance, back, stance.heading, cfg.carry, lambda xy: ground(xy), backward_max_m=1.0)
    for st in steps:
        stance = stance.apply(st)
    steps += walk_steps(stance, mid_xy, heading, cfg.carry, lambda xy: ground(xy), then=steps)
    held = ctx.held  # the box's squeeze (squeeze_for) and weight on the hands; none held: no forces
    squeeze, load = (held.squeeze_n, held.box.mass_kg * GRAVITY) if held is not None else (0.0, 0.0)
    plan = yield from ctx.compute("carry", carry_plan, q0, steps, cfg.carry, posture, ctx.poses.com_offset_m + com_shift,
                                  squeeze, load)
    ctx.last_steps = plan
    traj = plan.trajectory
    if plan.sole_error_m > 0.03:
        raise GoalFailed(f"carry: the footsteps are out of the legs' reach (plan off by "
                         f"{plan.sole_error_m * 100:.0f} cm)")
    yield from ctx.run(traj)
