"""Footsteps for the whole-body controller: where the feet go (flat, turning, onto and off a
platform) and the whole-body reference that takes them.

Footstep plans (a list of Footstep: which foot, where its sole lands in 3D, its yaw):
  walk_steps      from the current stance to a goal stance (mid-point x, y and yaw): turn to face
                  the way, walk straight (forward or backward), turn to the final heading; a
                  leapfrog gait with at most `max_advance_m` of mid-point advance and `max_turn_rad`
                  of yaw per step; the trailing foot closes alongside at the end.
  step_up_steps   from a stance facing a platform's edge onto it (lead foot, then the other alongside)
  step_down_steps from a stance on a platform, backwards off it down to the floor

stepping_trajectory turns a plan into a WholeBodyTrajectory: swing feet in 3D (for a change of
level: up to the higher level + clearance first, across above it, then down), the stance yaw
followed by the pelvis, the CoM from ZMP preview control (the ZMP on the stance sole in single
support, moving between soles in double support), a pelvis height that follows the ground under
the feet (it rises after a foot lands higher and lowers before a foot steps down), the arms held in
a given posture (a held box goes with them, its known hand forces throughout), and every 10 ms
sample from the whole-body IK, warm-started and rate limited.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from g1_control.generator.whole_body import WholeBodyTrajectory, smoothstep, trajectory_from_configurations
from g1_control.generator.zmp_preview import ZmpPreviewController
from g1_control.ik.whole_body import WholeBodyIK
from g1_control.robot import g1
from g1_control.robot.dynamics import SOLE_FRAMES
from g1_control.rotations import rot_z, wrap_angle
from g1_control.scene import Block

LEFT, RIGHT = 0, 1
SOLE_HALF_LENGTH_M = 0.085
"""From the sole frame's centre to the front (and rear) contact points (robot/dynamics.py)."""
LEVEL_CHANGE_M = 0.02
"""A step changes level when its sole lands more than this above or below where it was. Less is
the same floor: a whole-body pose's soles sit a few micrometres off the ground (IK residual), and
taking that for a step down leaned the pelvis 0.3 rad and lowered it 2 cm before the first
correcting step after a carry, and the robot fell (launch: a floor box carried to a 0.75 m table)."""


@dataclass(frozen=True)
class Footstep:
    foot: int
    """0 left, 1 right."""
    pos_w_m: np.ndarray
    """Where the sole frame lands (z: the surface there)."""
    yaw_rad: float
    swing_s: float | None = None
    """Single-support time of this step (None: SteppingConfig.single_support_s)."""


@dataclass
class Stance:
    """Both soles: positions (2, 3) and yaws (2,), left then right."""

    pos: np.ndarray
    yaw: np.ndarray

    @classmethod
    def of(cls, ik: WholeBodyIK, q: np.ndarray) -> Stance:
        pos, yaw = np.zeros((2, 3)), np.zeros(2)
        for i, name in enumerate(SOLE_FRAMES):
            p, r = ik.frame_pose(q, name)
            pos[i], yaw[i] = p, math.atan2(r[1, 0], r[0, 0])
        return cls(pos, yaw)

    def copy(self) -> Stance:
        return Stance(self.pos.copy(), self.yaw.copy())

    @property
    def mid_xy(self) -> np.ndarray:
        return self.pos[:, :2].mean(axis=0)

    @property
    def heading(self) -> float:
        return float(math.atan2(np.sin(self.yaw).sum(), np.cos(self.yaw).sum()))

    def apply(self, step: Footstep) -> Stance:
        out = self.copy()
        out.pos[step.foot] = step.pos_w_m
        out.yaw[step.foot] = step.yaw_rad
        return out


@dataclass
class SteppingConfig:
    single_support_s: float = 0.45
    double_support_s: float = 0.15
    level_double_support_s: float = 0.4
    """Double support before a step up or down (the body rises or lowers through it)."""
    lift_m: float = 0.05
    """Swing apex above the start for a step on level ground."""
    clearance_m: float = 0.06
    """Swing apex above the higher level for a step up or down."""
    level_swing_s: float = 0.9
    """Single-support time of a step up or down."""
    start_s: float = 0.4
    end_s: float = 1.0
    pelvis_above_ground_m: float = 0.74
    """Pelvis height above the ground under the feet while stepping (nominal standing: 0.756)."""
    descend_below_m: float = 0.05
    """Stepping down, the pelvis lowers this much further (module docstring of _pelvis_heights)."""
    swing_rotation_weight: float = 1.0
    """IK weight of a swing sole's orientation (stance soles: 1000): the swing foot may pitch when
    its leg folds high behind the body (a flat foot there would need more than the ankle's range)."""
    descent_lean_rad: float = 0.3
    """Pelvis pitch (forward lean) while stepping down: the hips go back toward the lower foot while
    the CoM stays over the stance foot, which keeps the stance ankle within its range."""
    level_zmp_back_m: float = 0.03
    """In the single support of a step up or down, the ZMP is this far behind the stance sole's
    centre (on level ground: under the CoM's standing offset, ~3 cm ahead)."""
    knee_margin_rad: float = 0.3
    """No knee straighter than this from its limit (0.21 rad): a straight knee is singular for the
    tracker (a trailing leg stretched back at lift-off drove the knee past its limit, measured)."""
    upper_body_posture_weight: float = 2.0
    """IK weight of the waist and arms' posture (legs: 0.002): the arms hold their pose (and a box),
    the waist stays put rather than bending to its limits for the CoM."""
    ankle_margin_rad: float = 0.15
    """Stance ankles keep their pitch this far inside its limits: the tracker needs ankle torque to
    balance (a swing ankle may use its whole range)."""
    stance_width_m: float = 0.237
    """Sole centre to sole centre, side to side (the default pose's)."""
    max_advance_m: float = 0.15
    """Mid-point advance per step (a foot moves up to twice this)."""
    max_side_m: float = 0.08
    max_turn_rad: float = 0.2
    dt_s: float = 0.01
    ik_iterations: int = 20
    max_joint_speed_radps: float = 10.0
    max_joint_accel_radps2: float = 300.0
    max_root_speed: float = 1.0
    """Limits on the change from one IK sample to the next: a guard against an IK that jumps
    between solutions (the tracker would get steps), well above what the plans need (a 0.9 s step
    up swings the knee at up to 8.5 rad/s)."""


# -- footstep plans --------------------------------------------------------------------------------
def _foot_at(mid_xy: np.ndarray, yaw: float, foot: int, width: float, z: float) -> np.ndarray:
    side = 1.0 if foot == LEFT else -1.0
    return np.array([mid_xy[0] - side * math.sin(yaw) * width / 2, mid_xy[1] + side * math.cos(yaw) * width / 2, z])


def _segment(stance: Stance, mid_to: np.ndarray, yaw_to: float, cfg: SteppingConfig,
             ground: Callable[[np.ndarray], float], steps: list[Footstep]) -> Stance:
    """Steps that take the mid-point to mid_to with heading yaw_to (straight, interpolated). The
    feet keep alternating from the last step of `steps` (a foot stepping twice in a row leaves the
    other in single support twice as long: a carry with a box tipped over it, measured); the first
    foot of all leads on the side of the motion."""
    mid0, yaw0 = stance.mid_xy, stance.heading
    d = mid_to - mid0
    c, s = math.cos(yaw0), math.sin(yaw0)
    along, side = c * d[0] + s * d[1], -s * d[0] + c * d[1]
    dyaw = float(wrap_angle(yaw_to - yaw0))
    if np.hypot(*d) < 1e-3 and abs(dyaw) < 1e-3:
        return stance
    n = max(1, math.ceil(max(abs(along) / cfg.max_advance_m, abs(side) / cfg.max_side_m,
                             abs(dyaw) / cfg.max_turn_rad) - 1e-9))
    if steps:
        first = 1 - steps[-1].foot
    else:
        first = LEFT if (side > 0.02 or (abs(side) <= 0.02 and dyaw > 0)) else RIGHT
    for k in range(1, n + 1):
        a = k / n
        mid, yaw = mid0 + a * d, yaw0 + a * dyaw
        foot = first if k % 2 else 1 - first
        pos = _foot_at(mid, yaw, foot, cfg.stance_width_m, 0.0)
        pos[2] = ground(pos[:2])
        step = Footstep(foot, pos, float(yaw))
        steps.append(step)
        stance = stance.apply(step)
    return stance


def _close(stance: Stance, cfg: SteppingConfig, ground: Callable[[np.ndarray], float],
           steps: list[Footstep]) -> Stance:
    """The trailing foot alongside the last one."""
    if not steps:
        return stance
    last = steps[-1]
    trailing = 1 - last.foot
    side = 1.0 if last.foot == LEFT else -1.0
    mid = last.pos_w_m[:2] - side * cfg.stance_width_m / 2 * np.array([-math.sin(last.yaw_rad), math.cos(last.yaw_rad)])
    pos = _foot_at(mid, last.yaw_rad, trailing, cfg.stance_width_m, 0.0)
    pos[2] = ground(pos[:2])
    step = Footstep(trailing, pos, last.yaw_rad)
    steps.append(step)
    return stance.apply(step)


def walk_steps(stance: Stance, goal_mid_xy: np.ndarray, goal_yaw: float, cfg: SteppingConfig,
               ground: Callable[[np.ndarray], float] = lambda xy: 0.0, *, backward_max_m: float = 0.6,
               turn_first_m: float = 0.4, then: list[Footstep] | None = None) -> list[Footstep]:
    """Footsteps from `stance` to a stance centred at goal_mid_xy facing goal_yaw: turn to face the
    way, walk straight, turn to the goal's heading (short moves backwards without turning), the
    trailing foot closing alongside at the end. The feet alternate on from `then` (steps planned
    before these; not repeated in the result)."""
    steps: list[Footstep] = list(then or [])
    before = len(steps)
    goal_mid_xy = np.asarray(goal_mid_xy, dtype=float)
    d = goal_mid_xy - stance.mid_xy
    dist = float(np.hypot(*d))
    if dist > turn_first_m:
        facing = float(wrap_angle(math.atan2(d[1], d[0]) - stance.heading))
        if dist <= backward_max_m and abs(wrap_angle(facing - math.pi)) < math.radians(30):
            way = stance.heading
        else:
            way = stance.heading + facing
        stance = _segment(stance, stance.mid_xy, way, cfg, ground, steps)
        stance = _segment(stance, goal_mid_xy, way, cfg, ground, steps)
    stance = _segment(stance, goal_mid_xy, goal_yaw, cfg, ground, steps)
    if len(steps) > before:
        _close(stance, cfg, ground, steps)
    return steps[before:]


def approach_stance_for_edge(block: Block, edge_point_xy: np.ndarray, normal_xy: np.ndarray, toe_gap_m: float,
                             cfg: SteppingConfig) -> tuple[np.ndarray, float]:
    """Mid-point and heading of a stance facing an edge (outward normal `normal_xy`) with the toes
    `toe_gap_m` short of it."""
    n = np.asarray(normal_xy, dtype=float) / np.linalg.norm(normal_xy)
    mid = np.asarray(edge_point_xy, dtype=float) + n * (SOLE_HALF_LENGTH_M + toe_gap_m)
    return mid, math.atan2(-n[1], -n[0])


def level_steps(stance: Stance, forward_m: float, level_z: float, cfg: SteppingConfig, lead: int = LEFT) -> list[Footstep]:
    """Both feet, one after the other, `forward_m` along the heading (negative: backwards) onto
    ground at height level_z (a step up or down)."""
    yaw = stance.heading
    mid = stance.mid_xy + forward_m * np.array([math.cos(yaw), math.sin(yaw)])
    steps = []
    for foot in (lead, 1 - lead):
        pos = _foot_at(mid, yaw, foot, cfg.stance_width_m, level_z)
        steps.append(Footstep(foot, pos, yaw, cfg.level_swing_s))
    return steps


# -- the whole-body reference ------------------------------------------------------------------------
@dataclass
class SteppingPlan:
    """What stepping_trajectory made, for checks and figures."""

    trajectory: WholeBodyTrajectory
    feet_w_m: np.ndarray
    zmp_xy_m: np.ndarray
    com_xy_m: np.ndarray
    pelvis_z_m: np.ndarray
    end_stance: Stance
    sole_error_m: float
    """Largest distance between a planted sole in the IK's poses and its plan (feasibility)."""
    extras: dict = field(default_factory=dict)


def _swing(p0: np.ndarray, p1: np.ndarray, tau: np.ndarray, cfg: SteppingConfig) -> tuple[np.ndarray, np.ndarray]:
    """Swing-foot positions (n, 3) and horizontal progress (n,) over tau in [0, 1]."""
    out = np.zeros((len(tau), 3))
    if abs(p1[2] - p0[2]) < LEVEL_CHANGE_M:
        a = smoothstep(tau)
        out[:] = p0 + a[:, None] * (p1 - p0)
        out[:, 2] += cfg.lift_m * (1 - np.cos(2 * np.pi * tau)) / 2
        return out, a
    apex = max(p0[2], p1[2]) + cfg.clearance_m
    a = smoothstep((tau - 0.15) / 0.5)  # across, above the higher level
    out[:, :2] = p0[:2] + a[:, None] * (p1[:2] - p0[:2])
    up, down = smoothstep(tau / 0.35), smoothstep((tau - 0.65) / 0.35)
    out[:, 2] = p0[2] + up * (apex - p0[2]) + down * (p1[2] - apex)
    return out, a


def stepping_trajectory(ik: WholeBodyIK, q0: np.ndarray, footsteps: list[Footstep], cfg: SteppingConfig | None = None,
                        *, posture: np.ndarray | None = None, hand_forces: np.ndarray | None = None,
                        com_offset_h_m: np.ndarray | None = None, name: str = "steps") -> SteppingPlan:
    """The whole-body reference that takes `footsteps` from configuration q0 (module docstring).

    posture: the 29 joints' target (arms held there; legs follow the feet); default: q0's.
    hand_forces: (2, 3) known hand forces held throughout (a carried box).
    com_offset_h_m: the CoM's place relative to the stance's centre (heading frame; default: as in q0).
    """
    cfg = cfg or SteppingConfig()
    pin = ik.pin
    stance = Stance.of(ik, q0)
    com0 = ik.com(q0)
    if com_offset_h_m is None:
        y0 = stance.heading
        rel = com0[:2] - stance.mid_xy
        com_offset_h_m = np.array([math.cos(y0) * rel[0] + math.sin(y0) * rel[1],
                                   -math.sin(y0) * rel[0] + math.cos(y0) * rel[1]])
    posture = q0[7:].copy() if posture is None else np.asarray(posture, dtype=float)

    def offset_w(yaw: float) -> np.ndarray:
        c, s = math.cos(yaw), math.sin(yaw)
        o = com_offset_h_m
        return np.array([c * o[0] - s * o[1], s * o[0] + c * o[1]])

    durations = [(st.swing_s or cfg.single_support_s) for st in footsteps]
    doubles = []
    level = stance.copy()
    for st in footsteps:
        changes = abs(st.pos_w_m[2] - level.pos[st.foot, 2]) > LEVEL_CHANGE_M
        doubles.append(cfg.level_double_support_s if changes else cfg.double_support_s)
        level = level.apply(st)
    total = cfg.start_s + sum(durations) + sum(doubles) + cfg.double_support_s + cfg.end_s
    t = np.arange(0.0, total + 1e-9, cfg.dt_s)
    n = len(t)
    feet = np.repeat(stance.pos[None], n, axis=0)
    yaws = np.repeat(stance.yaw[None], n, axis=0)
    contacts = np.ones((n, 2), dtype=bool)
    zmp = np.repeat((stance.mid_xy + offset_w(stance.heading))[None], n, axis=0)
    # (double support from, swing from, touchdown, lowest sole before/after, mean sole height before/after,
    #  the other foot's height)
    levels: list[tuple] = []
    """Per step: (double support start, swing start, touchdown, lower foot before/after, mean before/after,
    the other foot's height, whether it steps down by more than LEVEL_CHANGE_M)."""
    current = stance.copy()
    prev_zmp = zmp[0].copy()
    t0 = cfg.start_s
    for step, swing_s, ds_s in zip(footsteps, durations, doubles):
        other = 1 - step.foot
        level_change = abs(step.pos_w_m[2] - current.pos[step.foot, 2]) > LEVEL_CHANGE_M
        # Stepping up or down, the ZMP sits toward the heel: the hips stay nearer the lower foot.
        along = -cfg.level_zmp_back_m if level_change else com_offset_h_m[0]
        stance_zmp = current.pos[other, :2] + _rotate(np.array([along, 0.0]), current.yaw[other])
        ds = (t >= t0) & (t < t0 + ds_s)
        zmp[ds] = prev_zmp + ((t[ds] - t0) / ds_s)[:, None] * (stance_zmp - prev_zmp)
        ts = t0 + ds_s
        ss = (t >= ts) & (t < ts + swing_s)
        zmp[ss] = stance_zmp
        tau = (t[ss] - ts) / swing_s
        path, progress = _swing(current.pos[step.foot], step.pos_w_m, tau, cfg)
        feet[ss, step.foot] = path
        yaw_from = current.yaw[step.foot]
        yaw_to = yaw_from + float(wrap_angle(step.yaw_rad - yaw_from))
        yaws[ss, step.foot] = yaw_from + progress * (yaw_to - yaw_from)
        contacts[ss, step.foot] = False
        after = t >= ts + swing_s
        feet[after, step.foot] = step.pos_w_m
        yaws[after, step.foot] = yaw_to
        zmp[after] = stance_zmp
        nxt = current.apply(step)
        nxt.yaw[step.foot] = yaw_to
        levels.append((t0, ts, ts + swing_s, current.pos[:, 2].min(), nxt.pos[:, 2].min(),
                       current.pos[:, 2].mean(), nxt.pos[:, 2].mean(), current.pos[other, 2],
                       level_change and step.pos_w_m[2] < current.pos[step.foot, 2]))
        current = nxt
        prev_zmp = stance_zmp
        t0 = ts + swing_s
    final = current.mid_xy + offset_w(current.heading)
    ds = t >= t0
    zmp[ds] = prev_zmp + np.clip((t[ds] - t0) / cfg.double_support_s, 0, 1)[:, None] * (final - prev_zmp)
    pelvis_z = _pelvis_heights(t, levels, stance, cfg)
    z_start = q0[2]
    pelvis_z = pelvis_z + (z_start - pelvis_z[0]) * (1 - smoothstep(t / max(cfg.start_s, 1e-6)))
    preview = ZmpPreviewController(cfg.dt_s, max(com0[2] - stance.pos[:, 2].min(), 0.4))
    com_xy, _, _ = preview.plan(zmp, com0[:2])
    mean_yaw = np.arctan2(np.sin(yaws).sum(axis=1), np.cos(yaws).sum(axis=1))
    mean_yaw = np.unwrap(mean_yaw)
    qs = np.zeros((n, ik.model.nq))
    q = q0.copy()
    v_prev = np.zeros(ik.model.nv)
    lim = np.concatenate([np.full(6, cfg.max_root_speed), np.full(g1.NUM_JOINTS, cfg.max_joint_speed_radps)])
    sole_error = 0.0
    margin = np.full(g1.NUM_JOINTS, 0.02)
    for joint in ("left_knee_joint", "right_knee_joint"):
        margin[g1.JOINT_INDEX[joint]] = cfg.knee_margin_rad
    ankles = [g1.JOINT_INDEX[joint] for joint in ("left_ankle_pitch_joint", "right_ankle_pitch_joint")]
    lean = np.zeros(n)
    for t_ds, t_sw, t_td, _lo0, _lo1, _m0, _m1, _z, down in levels:
        if down:
            lean += cfg.descent_lean_rad * (smoothstep((t - t_ds) / max(t_sw - t_ds + 0.3 * (t_td - t_sw), 1e-6))
                                            - smoothstep((t - t_td) / (cfg.double_support_s + 0.3)))
    weights = np.full((2, 6), 1000.0)
    posture_w = np.where(np.isin(np.arange(g1.NUM_JOINTS), g1.LEG_JOINTS), 0.002, cfg.upper_body_posture_weight)
    for k in range(n):
        soles = [(feet[k, i], rot_z(yaws[k, i])) for i in range(2)]
        weights[:, 3:] = np.where(contacts[k], 1000.0, cfg.swing_rotation_weight)[:, None]
        margin[ankles] = np.where(contacts[k], cfg.ankle_margin_rad, 0.1)
        pelvis_rot = rot_z(mean_yaw[k]) @ _rot_y(lean[k]) if lean[k] else rot_z(mean_yaw[k])
        q_new = ik.solve(q, soles, com_xy[k], pelvis_z[k], pelvis_rot, posture, sole_weight=weights,
                         com_weight=100.0, pelvis_z_weight=100.0, pelvis_rot_weight=(10.0, 3.0, 10.0),
                         margin_rad=margin,
                         posture_weight=posture_w,
                         iterations=cfg.ik_iterations if k else 40)
        if k:
            v = pin.difference(ik.model, q, q_new) / cfg.dt_s
            dv = cfg.max_joint_accel_radps2 * cfg.dt_s
            v[6:] = np.clip(v[6:], v_prev[6:] - dv, v_prev[6:] + dv)
            scale = np.max(np.abs(v) / lim)
            if scale > 1.0:
                v /= scale
            q_new = pin.integrate(ik.model, q, v * cfg.dt_s)
            v_prev = v
        q = q_new
        qs[k] = q
        if k % 5 == 0 or k == n - 1:
            for i, fname in enumerate(SOLE_FRAMES):
                if contacts[k, i]:  # a planted sole off its place is a plan the legs cannot take
                    sole_error = max(sole_error, float(np.linalg.norm(ik.frame_pose(q, fname)[0] - feet[k, i])))
    forces = None if hand_forces is None else np.repeat(np.asarray(hand_forces, dtype=float)[None], n, axis=0)
    traj = trajectory_from_configurations(name, t, qs, contacts, forces)
    return SteppingPlan(traj, feet, zmp, com_xy, pelvis_z, current, sole_error)


STRAIGHT_KNEE_GUARD_M = 0.03
"""The pelvis stays within this of the nominal height above the lower foot (a straight knee is
singular for the tracker and leaves it no way to push)."""


def _pelvis_heights(t: np.ndarray, levels, stance: Stance, cfg: SteppingConfig) -> np.ndarray:
    """Pelvis height over time: the nominal height above the mean level of the feet.

    A swing foot counts where it left until it has landed higher: the body rises through the
    double support after a step up, but no higher than the nominal height (+ guard) over the lower
    foot, so it does not rise further when the trailing foot lifts (rising while the trailing leg
    swings up made the tracker throw the body up 6-10 cm and the stance foot slip, measured in the
    issue 17 investigation and here). Stepping down, the body lowers through the double support
    and most of the swing before the foot lands, further than the mean: to the nominal height
    above the lower level less `descend_below_m` (the leg reaching down is stretched out along the
    step), never above the lower foot's nominal height + STRAIGHT_KNEE_GUARD_M afterwards."""
    g = STRAIGHT_KNEE_GUARD_M
    mean_moves: list[tuple[float, float, float]] = []
    extra_moves: list[tuple[float, float, float]] = []
    for t_ds, t_sw, t_td, _lo0, lo1, m0, m1, _z_stance, down in levels:
        settle = t_td + cfg.double_support_s + 0.3
        if down:  # stepping down (by more than LEVEL_CHANGE_M)
            before = t_sw + 0.7 * (t_td - t_sw)
            mean_moves.append((t_ds, before, m1))
            extra_moves.append((t_ds, before, min(0.0, lo1 + g - cfg.descend_below_m - m1)))
            extra_moves.append((t_td, settle, min(0.0, lo1 + g - m1)))
        elif m1 > m0 + 1e-6:  # stepping up: the body rises once the foot has landed, as far as
            # the lower leg allows (it stays low while the trailing leg swings up)
            rise = (t_td, t_td + cfg.level_double_support_s)
            mean_moves.append((*rise, m1))
            extra_moves.append((*rise, min(0.0, lo1 + g - m1)))
    mean = _transitions(t, float(stance.pos[:, 2].mean()), mean_moves)
    extra = _transitions(t, 0.0, extra_moves)
    return mean + extra + cfg.pelvis_above_ground_m


def _transitions(t: np.ndarray, start: float, moves: list[tuple[float, float, float]]) -> np.ndarray:
    """A signal that starts at `start` and moves to each (t_from, t_to, value) in turn, smoothly."""
    out = np.full(len(t), start)
    for t_from, t_to, value in sorted(moves):
        now = float(np.interp(t_from, t, out))
        w = t >= t_from
        out[w] = now + (value - now) * smoothstep((t[w] - t_from) / max(t_to - t_from, 1e-6))
    return out


def _rot_y(pitch: float) -> np.ndarray:
    c, s = math.cos(pitch), math.sin(pitch)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def _rotate(v: np.ndarray, yaw: float) -> np.ndarray:
    c, s = math.cos(yaw), math.sin(yaw)
    return np.array([c * v[0] - s * v[1], s * v[0] + c * v[1]])


__all__ = ["Footstep", "Stance", "SteppingConfig", "SteppingPlan", "approach_stance_for_edge", "level_steps",
           "stepping_trajectory", "walk_steps"]
