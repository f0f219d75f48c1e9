"""`InbetweeningGenerator`: the runtime Generator (operator Command -> KinematicReference each tick).

Planning follows MotionBricks' loop: a plan is a buffer of future frames at the planning rate
(30 fps). A new plan is made when the command changes (velocity, heading, style, height, goals)
or when fewer than `replan_low_frames` frames are left. A plan takes the last 10 executed frames
as context, asks the smart primitives for a target keyframe (partially given), lets the
in-betweener fill the gap, and is cross-faded into the old plan over a few frames so the
reference never jumps. Frames are generated in the canonical frame of the last context frame,
so nothing depends on how far the robot has walked.

Long-horizon stability (COMET's point: autoregressive generation drifts off the pose manifold
unless fed back towards it): every plan is checked and corrected before it is used - joints
clamped to the robot's limits, the pelvis height kept within the style's observed range (plus
margin), the root kept upright within the library's tilt, and a plan that is not finite is
replaced by interpolation toward the keyframe (counted in `fallbacks`). With a
ReferenceFeedback (feedback.py) every plan's poses are also attracted toward the current style's
reference mixture, except near a goal.

Joint-level goals: Command.goals on hands, feet, head or the pelvis (EffectorGoal) become goals
inside the model. A goal beyond arm's reach is walked to first (a stance point next to it,
facing it - the WANDR-style reaching setup), then given on the keyframe and on gap frames: from
the frame the effector can reach it at hand speed, held every 2 frames to the plan's end (a goal
on one frame only is touched and left: measured, the model keeps a goal local to its token), or
on the frame of its t_s when that falls inside the plan. The goal-error feedback adds the model's
own remaining error at the goal frame (FK of its joints, no IK) to the next plan's goal. The skeleton (29-DoF,
23-DoF, with hands) is an input of the model; joints it lacks stay at 0 and, on the G1 with hands,
the reference carries the finger angles (KinematicReference.hand_q_rad).

Its references are not feasible by construction (no feasible_plan): the IK stage
(g1_control/ik/stage.py) makes them so (limits, smoothness, effector goals as frame targets). The
plan's heading-frame root velocity passes through the IK as the walking tracker's command, and
the references ask for the upper body (upper_body_override), so the policy walks the generated
root path while waist and arms follow the generated pose.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from g1_control.generator import features as F
from g1_control.generator import skeleton as S
from g1_control.generator.feedback import ReferenceFeedback
from g1_control.generator.foot_lock import end_given, lock_feet
from g1_control.generator.inbetween import CONTEXT_FRAMES, Inbetweener
from g1_control.generator.primitives import (
    Keyframe,
    RootState,
    SpringConfig,
    box_approach,
    hand_targets_on_box,
    root_features,
    spring_root_trajectory,
)
from g1_control.generator.style_stats import StyleStats
from g1_control.generator.styles import STYLES, style_id
from g1_control.interfaces import Generator
from g1_control.robot import g1
from g1_control.types import Command, KinematicReference, RobotState

_WAIST_LEAN = [F.JOINTS.start + g1.JOINT_INDEX[name] for name in ("waist_roll_joint", "waist_pitch_joint")]
"""Feature columns of waist roll and pitch."""

OBJECT_GOALS = ("box_pick", "box_climb")
"""EffectorGoal.frame values that name an object goal instead of a robot frame; pos_w_m is then
the centre of a box standing on the floor."""
GOAL_FRAMES = F.EFFECTOR_BODIES + ("head_link", g1.BASE_BODY)
"""EffectorGoal.frame values the model takes as joint-level goals ('head' and 'head_link' are the
head point; 'pelvis' is the root position)."""
STANCE_OFFSET = {"left_wrist_yaw_link": (0.22, 0.2), "right_wrist_yaw_link": (0.22, -0.2), "head": (0.1, 0.0)}
"""Where a reaching goal sits relative to the pelvis once there (m, heading frame: forward, left);
for a hand, the forward distance shrinks for goals far above or below the shoulder
(`hand_forward_m`)."""
SHOULDER_ABOVE_PELVIS_M = 0.29
ARM_REACH_M = 0.30
"""Shoulder-pitch joint to wrist-yaw link of the G1, arm straight (0.28 m) plus a little lean."""


def hand_forward_m(goal_z: float, pelvis_z: float, most: float = 0.22) -> float:
    """How far ahead of the pelvis a hand goal at goal_z can be reached standing (m)."""
    dz = goal_z - (pelvis_z + SHOULDER_ABOVE_PELVIS_M)
    return float(np.clip(math.sqrt(max(0.0, ARM_REACH_M ** 2 - dz * dz)) - 0.03, 0.05, most))


def _effector_fk(frame: np.ndarray, name: str) -> np.ndarray:
    """An effector's position in a world-frame feature frame by forward kinematics of its root and
    joints (the model's own pose, not its effector columns)."""
    from g1_control.motion.kinematics import default_body_names

    pos, rot = F.bodies_of(frame)
    return F.effectors_from_bodies(pos, rot, default_body_names())[F.EFFECTOR_BODIES.index(name)]


@dataclass
class RuntimeConfig:
    fps: float = 30.0
    horizon_frames: int = 30
    replan_low_frames: int = 12
    crossfade_frames: int = 8
    spring: SpringConfig = field(default_factory=SpringConfig)
    height_margin_m: float = 0.05
    max_tilt_rad: float = 0.5
    box_standoff_m: float = 0.45
    box_half_width_m: float = 0.2
    command_tolerance: float = 0.02
    velocity_window_frames: int = 30
    velocity_deadband_mps: float = 0.06
    yaw_rate_deadband_radps: float = 0.06
    max_waist_lean_rad: float = 0.2
    """Plans keep waist roll and pitch within this. The library's style recordings made before the
    styled-walking tracker sagged the waist pitch to its 0.52 rad limit (carry, wave, reach_up in
    style_stats.json: 0.48-0.52), which no style intends; the tracker leaves waist roll/pitch to
    the walking policy in any case."""
    reach_radius_m: float = 0.15
    """A reaching goal's stance point counts as reached within this distance (then latched)."""
    reach_early_m: float = 0.35
    """While walking to a stance point, the goal joins the keyframe once the spring's keyframe
    root is this close to it."""
    goal_error_gain: float = 0.7
    """Goal-error feedback: after each plan, this fraction of the error left at an effector goal's
    frame - forward kinematics of the model's planned joints, no IK - is added to the goal the
    model is given next time (an integrator on the model's static error, at most goal_error_max_m,
    updated while the error is under goal_error_near_m). 0 disables."""
    goal_error_near_m: float = 0.3
    goal_error_max_m: float = 0.2
    effector_speed_mps: float = 0.5
    """A goal near its effector is put on the gap frame the effector reaches at this speed..."""
    min_goal_frame: int = 8
    """... but not before this frame (0-based)."""
    hold_every_frames: int = 2
    """A goal without a time is held: given again every this many frames after its first frame."""
    foot_lock: bool = True
    """Hold each plan's stance feet where they stand (foot_lock.py: the backbone's stance feet slide
    about 0.2 m/s at gap 30 without it; a controller that follows the plan's feet would slide with them)."""
    velocity_feedback_gain: float = 0.3
    """Plan-velocity feedback: at each plan, this fraction of the error between the command's (vx, vy,
    wz) and the plan's own over the last `velocity_feedback_frames` (its executed frames, heading frame)
    is added to what the primitives are asked for (an integrator, at most velocity_feedback_max per
    axis, restarted when the command changes), walking without a commanded turn. The in-betweener does not land exactly on its target
    keyframes: open loop it planned 0.30-0.37 m/s sideways for 0.25 and drifted 0.06-0.20 m/s sideways
    and 0.03-0.13 rad/s in yaw walking 0.5-0.6 m/s forward (measured, five styles); a tracker that walks
    the plan (the whole-body controller) walks those errors. 0 disables."""
    velocity_feedback_frames: int = 30
    velocity_feedback_settle_s: float = 2.0
    """The integrator starts this long after the command changed (the window must hold only this
    command's settled plan: from 0.5 m/s forward to 0.3 back, it read the turnaround as error and
    the whole-body controller walked back at 0.37, measured)."""
    velocity_feedback_max: tuple[float, float, float] = (0.3, 0.3, 0.4)


@dataclass
class PlanStats:
    replans: int = 0
    fallbacks: int = 0
    replan_reasons: dict[str, int] = field(default_factory=dict)


def _same_command(a: Command | None, b: Command, tol: float) -> bool:
    if a is None:
        return False
    if a.style != b.style or (a.heading_rad is None) != (b.heading_rad is None):
        return False
    if a.pelvis_height_m != b.pelvis_height_m or len(a.goals) != len(b.goals):
        return False
    for ga, gb in zip(a.goals, b.goals):
        if ga.frame != gb.frame or not np.allclose(ga.pos_w_m, gb.pos_w_m, atol=1e-3):
            return False
    diff = [a.vx_mps - b.vx_mps, a.vy_mps - b.vy_mps, a.wz_radps - b.wz_radps,
            (a.heading_rad or 0.0) - (b.heading_rad or 0.0)]
    return max(abs(d) for d in diff) < tol


class InbetweeningGenerator(Generator):
    def __init__(self, inbetweener: Inbetweener, styles: dict[str, StyleStats], config: RuntimeConfig | None = None,
                 skeleton: str = "g1_29dof", feedback: ReferenceFeedback | None = None):
        self.model = inbetweener
        self.styles = styles
        self.config = config or RuntimeConfig()
        self.skeleton = S.skeleton(skeleton)
        self.present = F.present_mask(self.skeleton.present)
        self.feedback = feedback
        self._reach: dict[str, list] = {}
        self._goal_offset: dict[str, tuple] = {}
        self._gap_goals: list[tuple] = []  # (frame, columns, value given, goal name, goal point)
        self.stats = PlanStats()
        self.ref = KinematicReference(upper_body_override=True)
        self._dt = 1.0 / self.config.fps
        self.history = np.zeros((0, F.DIM))
        self.plan = np.zeros((0, F.DIM))
        self.plan_t0 = 0.0
        self._last_cmd: Command | None = None
        self._frame_targets: dict[str, np.ndarray] = {}
        self._style = "default"
        self._object: list | None = None
        self._t = 0.0

    # ------------------------------------------------------------------ lifecycle
    def reset(self, state: RobotState) -> None:
        pos = state.base_pos_w_m if state.base_pos_w_m is not None else np.array([0, 0, g1.DEFAULT_PELVIS_HEIGHT_M])
        w, x, y, z = state.imu_quat_wxyz
        yaw = math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))
        frame = np.zeros(F.DIM)
        frame[F.ROOT] = root_features(np.asarray(pos[:2], float), float(pos[2]), yaw)
        frame[F.JOINTS] = state.q_rad
        frame = F.fix_effectors(frame[None])[0] * self.present
        self.reset_from_frames(np.repeat(frame[None], CONTEXT_FRAMES, axis=0), state.t_s)

    def reset_from_frames(self, frames: np.ndarray, t_s: float = 0.0) -> None:
        """Start from recorded world-frame features (the last CONTEXT_FRAMES of them are the
        context of the first plan): e.g. an unseen start pose from held-out clips."""
        frames = np.asarray(frames, dtype=float)[-CONTEXT_FRAMES:] * self.present
        if len(frames) < CONTEXT_FRAMES:
            frames = np.concatenate([np.repeat(frames[:1], CONTEXT_FRAMES - len(frames), axis=0), frames])
        self.history = frames.copy()
        self.plan = frames[-1:].copy()
        self.plan_t0 = t_s
        self._t = t_s
        self._last_cmd = None
        self._object = None
        self._reach = {}
        self._goal_offset = {}
        self.stats = PlanStats()
        self._feedback = np.zeros(3)
        self._root_track = self.history[:, 0:5].copy()
        self._feedback_key: tuple | None = None
        self._feedback_from = 0.0

    # ------------------------------------------------------------------ planning
    def _root_state(self) -> RootState:
        h = self.history
        last, prev = h[-1], h[-2]
        yaw = math.atan2(last[4], last[3])
        yaw_prev = math.atan2(prev[4], prev[3])
        rate = ((yaw - yaw_prev + math.pi) % (2 * math.pi) - math.pi) * self.config.fps
        return RootState(last[0:2].copy(), (last[0:2] - prev[0:2]) * self.config.fps, yaw, rate)

    def _plan_velocity(self) -> np.ndarray | None:
        """(vx, vy, wz) of the plan's last velocity_feedback_frames executed frames (heading frame halfway
        through them), None while fewer have been executed."""
        n = self.config.velocity_feedback_frames
        h = self._root_track  # the executed frames' x, y, z and first 6D column (their heading)
        if len(h) <= n:
            return None
        first, last = h[-n - 1], h[-1]
        yaw0 = math.atan2(first[4], first[3])
        turned = ((math.atan2(last[4], last[3]) - yaw0 + math.pi) % (2 * math.pi) - math.pi)
        span = n / self.config.fps
        d = (last[0:2] - first[0:2]) / span
        # turning at a steady rate, the chord points along the heading halfway through
        c, s = math.cos(yaw0 + 0.5 * turned), math.sin(yaw0 + 0.5 * turned)
        return np.array([c * d[0] + s * d[1], -s * d[0] + c * d[1], turned / span])

    def _velocity_feedback(self, command: Command, v_cmd: np.ndarray, wz: float) -> tuple[np.ndarray, float]:
        """The command the primitives are asked for: `command` plus the plan-velocity integrator
        (RuntimeConfig.velocity_feedback_gain) while walking straight (forward, backward, sideways, with
        no turn commanded). Standing, turning, goals and headings are left alone."""
        cfg = self.config
        key = (command.vx_mps, command.vy_mps, command.wz_radps, command.style)
        if key != self._feedback_key:
            self._feedback_key = key
            self._feedback[:] = 0.0
            self._feedback_from = self._t
        # walking straight only: with a turn commanded, the feedback slowed the plan's forward speed
        # (0.3 m/s at 0.5 rad/s: 0.24-0.28 planned without it, 0.21-0.23 with it, measured)
        straight = max(abs(command.vx_mps), abs(command.vy_mps)) > cfg.velocity_deadband_mps and \
            abs(command.wz_radps) <= cfg.yaw_rate_deadband_radps
        if cfg.velocity_feedback_gain <= 0.0 or not straight:
            self._feedback[:] = 0.0
            return v_cmd, wz
        plan = self._plan_velocity()
        # the plan's last second must be this command's, the primitives' spring settled
        if plan is not None and self._t - self._feedback_from >= cfg.velocity_feedback_settle_s:
            err = np.array([command.vx_mps, command.vy_mps, command.wz_radps]) - plan
            lim = np.asarray(cfg.velocity_feedback_max)
            self._feedback[:] = np.clip(self._feedback + cfg.velocity_feedback_gain * err, -lim, lim)
        return v_cmd + self._feedback[:2], wz + float(self._feedback[2])

    def _style_stats(self, name: str) -> StyleStats:
        return self.styles.get(name) or self.styles["default"]

    def keyframe(self, command: Command) -> Keyframe:
        """The target keyframe the primitives make of `command` (world frame)."""
        cfg = self.config
        style = command.style if command.style in STYLES else "default"
        st = self._style_stats(style)
        gap = cfg.horizon_frames
        root = self._root_state()
        given = np.zeros(F.DIM, dtype=bool)
        values = np.zeros(F.DIM)
        targets: dict[str, np.ndarray] = {}
        height = command.pelvis_height_m if command.pelvis_height_m is not None else st.pelvis_height_m[1]
        obj = next((g for g in command.goals if g.frame in OBJECT_GOALS), None)
        v_cmd = np.array([command.vx_mps, command.vy_mps])
        wz, heading = command.wz_radps, command.heading_rad
        pose = st.upper_pose_rad
        if obj is None:
            self._object = None
            if heading is None:
                v_cmd, wz = self._velocity_feedback(command, v_cmd, wz)
        else:
            box = np.asarray(obj.pos_w_m, float)
            key_obj = (obj.frame, tuple(np.round(box, 3)))
            if self._object is None or self._object[0] != key_obj:
                spot, face = box_approach(box, root.pos_xy, cfg.box_standoff_m)
                self._object = [key_obj, spot, face, False]
            _, spot, face, acting = self._object
            dist = float(np.linalg.norm(spot - root.pos_xy))
            # Once at the spot, the object phase is latched: approaching the box from there
            # must not send the robot back to a spot recomputed from its new position.
            acting = self._object[3] = acting or dist <= 0.15
            if not acting:  # walk there: a velocity toward the spot, heading facing the box
                c, s = math.cos(root.yaw), math.sin(root.yaw)
                d = (spot - root.pos_xy) / dist * min(cfg.spring.max_vx_mps, dist)
                v_cmd = np.array([c * d[0] + s * d[1], -s * d[0] + c * d[1]])
                wz, heading = 0.0, face
            elif obj.frame == "box_pick" and "lift" in self.styles:
                lift = self.styles["lift"]
                style, pose = "lift", lift.upper_pose_rad
                height = lift.pelvis_height_m[0]
                targets = hand_targets_on_box(box, face, cfg.box_half_width_m)
                v_cmd, wz, heading = np.zeros(2), 0.0, face
            elif obj.frame == "box_climb":
                style = "climb"
                v_cmd, wz, heading = np.zeros(2), 0.0, face
                # the keyframe stands on the box: centre of its top face (pos_w_m is the centre of a
                # box resting on the floor, so the top is at twice its height)
                root = RootState(box[:2].copy(), np.zeros(2), face, 0.0)
                height = float(box[2]) * 2.0 + self._style_stats("default").pelvis_height_m[1]
        path, yaws = spring_root_trajectory(root, v_cmd, wz, heading, gap / cfg.fps, 1.0 / cfg.fps, cfg.spring)
        values[F.ROOT] = root_features(path[-1], height, float(yaws[-1]))
        given[F.ROOT] = True
        if style != "default" or obj is not None:
            ub = [9 + j for j in g1.UPPER_BODY_JOINTS]
            values[ub] = pose[list(g1.UPPER_BODY_JOINTS)]
            lean = cfg.max_waist_lean_rad
            values[_WAIST_LEAN] = np.clip(values[_WAIST_LEAN], -lean, lean)
            given[ub] = True
        self._gap_goals = []
        reaching = [g for g in command.goals if g.frame not in OBJECT_GOALS]
        if reaching and obj is None:
            root_xy, root_yaw, walk = self._reach_plan(reaching, root)
            if walk is not None:
                path, yaws = spring_root_trajectory(root, walk, 0.0, root_yaw, gap / cfg.fps, 1.0 / cfg.fps, cfg.spring)
                values[F.ROOT] = root_features(path[-1], height, float(yaws[-1]))
            else:
                values[F.ROOT] = root_features(root_xy, height, root_yaw)
        for goal in reaching:
            point = np.asarray(goal.pos_w_m, float)
            name = "head" if goal.frame == "head_link" else goal.frame
            targets[goal.frame] = np.concatenate([point, [1.0, 0.0, 0.0, 0.0]])
            if name not in F.EFFECTOR_BODIES and name != g1.BASE_BODY:
                continue  # another frame: the IK's frame target only
            if obj is None and not self._goal_active(name, values):
                continue
            if name in ("left_wrist_yaw_link", "right_wrist_yaw_link"):  # the goal's arm is free of the style pose
                arm = g1.ARM_JOINTS[:7] if name.startswith("left") else g1.ARM_JOINTS[7:]
                given[[F.JOINTS.start + j for j in arm]] = False
            frame = gap - 1
            if name == g1.BASE_BODY:
                cols = np.r_[0:3]
                given_point = point
            else:
                cols = np.r_[F.effector_slice(name)]
                given_point = point + self._goal_offset_for(name, point)
                # a goal close by is reached at hand speed, not at the plan's end (replanning comes
                # after replan_low_frames: a goal on the last frame would never be executed)
                dist = float(np.linalg.norm(_effector_fk(self.history[-1], name) - point))
                frame = int(np.clip(math.ceil(dist / cfg.effector_speed_mps * cfg.fps), cfg.min_goal_frame, gap - 1))
            values[cols] = given_point
            given[cols] = True
            if goal.t_s is not None:
                frame = int(np.clip(round(goal.t_s * cfg.fps) - 1, 0, gap - 1))
            self._gap_goals.append((frame, cols, given_point, name, point))
            if goal.t_s is None:  # held: the goal stays given on later frames of the plan too
                for later in range(frame + cfg.hold_every_frames, gap, cfg.hold_every_frames):
                    self._gap_goals.append((later, cols, given_point, None, point))
        given &= self.present
        return Keyframe(values, given, gap, style, targets)

    def _reach_plan(self, goals, root: RootState) -> tuple[np.ndarray, float, np.ndarray | None]:
        """Where to stand for the goals (their stance points, averaged) and, while not there, the
        heading-frame walking velocity toward it; (stance xy, facing yaw, velocity or None)."""
        cfg = self.config
        spots, faces = [], []
        for goal in goals:
            name = "head" if goal.frame == "head_link" else goal.frame
            point = np.asarray(goal.pos_w_m, float)
            key = (name, tuple(np.round(point, 3)))
            entry = self._reach.get(name)
            if entry is None or entry[0] != key:
                if name == g1.BASE_BODY:
                    d = point[:2] - root.pos_xy
                    face = math.atan2(d[1], d[0]) if np.linalg.norm(d) > 0.3 else root.yaw
                    spot = point[:2].copy()
                elif name in STANCE_OFFSET:
                    d = point[:2] - root.pos_xy
                    face = math.atan2(d[1], d[0]) if np.linalg.norm(d) > 0.2 else root.yaw
                    fx, fy = STANCE_OFFSET[name]
                    if name != "head":
                        fx = hand_forward_m(point[2], float(self.history[-1][2]), fx)
                    c, s_ = math.cos(face), math.sin(face)
                    spot = point[:2] - np.array([c * fx - s_ * fy, s_ * fx + c * fy])
                else:  # feet: step where the foot goes, facing as now
                    spot, face = root.pos_xy.copy(), root.yaw
                entry = self._reach[name] = [key, spot, face, False]
            spots.append(entry[1])
            faces.append(entry[2])
        spot = np.mean(spots, axis=0)
        face = float(math.atan2(np.mean(np.sin(faces)), np.mean(np.cos(faces))))
        dist = float(np.linalg.norm(spot - root.pos_xy))
        arrived = all(e[3] for e in self._reach.values()) or dist <= cfg.reach_radius_m
        for e in self._reach.values():
            e[3] = arrived
        if arrived:
            return spot, face, None
        c, s_ = math.cos(root.yaw), math.sin(root.yaw)
        d = (spot - root.pos_xy) / dist * min(cfg.spring.max_vx_mps, dist)
        return spot, face, np.array([c * d[0] + s_ * d[1], -s_ * d[0] + c * d[1]])

    def _goal_offset_for(self, name: str, point: np.ndarray) -> np.ndarray:
        """The goal-error feedback's current offset for an effector goal (0 for a new goal)."""
        prev = self._goal_offset.get(name)
        return prev[1] if prev is not None and prev[0] == tuple(np.round(point, 3)) else np.zeros(3)

    def _update_goal_errors(self, frames: np.ndarray) -> None:
        """After a plan: for each effector goal, the error of the planned frame that was to reach it
        (FK of the model's joints) feeds the offset given with that goal next time (an integrator on
        the model's static error; RuntimeConfig.goal_error_gain)."""
        cfg = self.config
        if cfg.goal_error_gain <= 0:
            return
        for frame, _, _, name, point in self._gap_goals:
            if name is None or name == g1.BASE_BODY or frame >= len(frames):
                continue
            error = point - _effector_fk(frames[frame], name)
            offset = self._goal_offset_for(name, point)
            if float(np.linalg.norm(error)) < cfg.goal_error_near_m:
                offset = offset + cfg.goal_error_gain * error
                norm = float(np.linalg.norm(offset))
                if norm > cfg.goal_error_max_m:
                    offset *= cfg.goal_error_max_m / norm
            self._goal_offset[name] = (tuple(np.round(point, 3)), offset)

    def _goal_active(self, name: str, values: np.ndarray) -> bool:
        """A goal joins the keyframe once its stance point is reached or about to be."""
        entry = self._reach.get(name)
        if entry is None or entry[3]:
            return True
        return float(np.linalg.norm(values[0:2] - entry[1])) < self.config.reach_early_m

    def _replan(self, command: Command, reason: str) -> None:
        cfg = self.config
        key = self.keyframe(command)
        context = self.history[-CONTEXT_FRAMES:]
        last = context[-1]
        origin = last[0:2].copy()
        yaw = math.atan2(last[4], last[3])  # heading of the pelvis x axis (first 6D column)
        ctx_c = F.transform_one(context, origin, yaw)[None]
        tgt_c = F.transform_one(key.values[None], origin, yaw)
        if self._gap_goals and hasattr(self.model, "set_goals"):
            goal = np.zeros((key.gap, F.DIM))
            mask = np.zeros((key.gap, F.DIM), dtype=bool)
            for frame, cols, point, _, _ in self._gap_goals:
                goal[frame, cols] = point
                mask[frame, cols] = True
            goal = F.transform_one(goal, origin, yaw)
            goal[~mask] = 0.0
            self.model.set_goals(goal[None], mask[None])
        frames_c = self.model.infill(ctx_c, tgt_c, key.given[None], key.gap, np.array([style_id(key.style)]))
        frames = F.transform_one(frames_c[0], origin, yaw, inverse=True)
        frames = self._stabilize(frames, key)
        if self._gap_goals:
            self._update_goal_errors(frames)
        # cross-fade: the old plan's frames still ahead (same times) blend into the new plan
        old = self.plan
        n = min(cfg.crossfade_frames, len(old), len(frames))
        if n:
            w = (np.arange(1, n + 1) / (n + 1))[:, None]
            frames[:n] = (1 - w) * old[:n] + w * frames[:n]
        if cfg.foot_lock:  # after the cross-fade: blending two plans' feet slides them
            frames = lock_feet(frames[None], self.history[-1][None], key.values[None],
                               end_given(key.given[None]))[0] * self.present
        self.plan = frames
        self._frame_targets = key.frame_targets_w
        self._style = key.style
        self.stats.replans += 1
        self.stats.replan_reasons[reason] = self.stats.replan_reasons.get(reason, 0) + 1

    def _stabilize(self, frames: np.ndarray, key: Keyframe) -> np.ndarray:
        cfg = self.config
        if not np.all(np.isfinite(frames)):
            from g1_control.generator.inbetween import interpolate

            self.stats.fallbacks += 1
            last = self.history[-1]
            frames = interpolate(last[None], np.where(key.given, key.values, last)[None], key.gap)[0]
        if self.feedback is not None:
            self.feedback.set_style(key.style)
            goal_frames = [f for f, *_ in self._gap_goals]
            eff = [(cols, point) for _, cols, _, _, point in self._gap_goals]
            weights = self.feedback.frame_weights(len(frames), goal_frames, key.gap if goal_frames else None,
                                                  frames, eff)
            frames = self.feedback.apply(frames, weights)
        frames[:, F.JOINT_SLOTS] = np.clip(frames[:, F.JOINT_SLOTS], self.skeleton.q_min, self.skeleton.q_max)
        frames[:, _WAIST_LEAN] = np.clip(frames[:, _WAIST_LEAN], -cfg.max_waist_lean_rad, cfg.max_waist_lean_rad)
        lo, _, hi = self._style_stats(key.style).pelvis_height_m
        floor = min(lo, key.values[2]) - cfg.height_margin_m
        ceil = max(hi, key.values[2]) + cfg.height_margin_m
        frames[:, 2] = np.clip(frames[:, 2], floor, ceil)
        # tilt from the 6D columns: the pelvis z axis' vertical component is x_x y_y - x_y y_x
        up = frames[:, 3] * frames[:, 7] - frames[:, 4] * frames[:, 6]
        if np.any(up < math.cos(cfg.max_tilt_rad)):
            rot = F.rot6d_to_matrix(frames[:, F.ROOT_ROT])
            tilt = np.arccos(np.clip(rot[:, 2, 2], -1.0, 1.0))
            upright = F.rot_z(F.yaw_of_matrix(rot))
            bad = tilt > cfg.max_tilt_rad
            rot[bad] = upright[bad]
            frames[:, 3:6], frames[:, 6:9] = rot[:, :, 0], rot[:, :, 1]
        # Effectors stay as the in-betweener made them (the backbone predicts them; FK here
        # would cost more than the model) - they feed contacts and the next plan's context.
        return frames

    # ------------------------------------------------------------------ per tick
    def _advance(self, t: float) -> None:
        """Plan frames whose time has come become history (the executed motion)."""
        k = math.floor((t - self.plan_t0) * self.config.fps + 1e-9)
        k = min(k, len(self.plan))
        if k > 0:
            self.history = np.concatenate([self.history, self.plan[:k]])[-CONTEXT_FRAMES:]
            self._root_track = np.concatenate([self._root_track, self.plan[:k, 0:5]])[-(self.config.velocity_feedback_frames + 1):]
            self.plan = self.plan[k:]
            self.plan_t0 += k * self._dt

    def update(self, command: Command, state: RobotState) -> KinematicReference:
        t = state.t_s
        if not len(self.history):
            self.reset(state)
        self._t = t
        self._advance(t)
        if not _same_command(self._last_cmd, command, self.config.command_tolerance):
            self._replan(command, "command")
            self._last_cmd = command
        elif len(self.plan) < self.config.replan_low_frames:
            self._replan(command, "buffer")
        if not len(self.plan):  # time jumped past a whole plan: plan again from where we are
            self._replan(command, "empty")
        return self._reference(t)

    def _reference(self, t: float) -> KinematicReference:
        a = float(np.clip((t - self.plan_t0) * self.config.fps, 0.0, 1.0))
        f0, f1 = self.history[-1], self.plan[0]
        frame = (1 - a) * f0 + a * f1
        rot = F.rot6d_to_matrix(frame[F.ROOT_ROT])
        ref = self.ref
        ref.t_s = t
        ref.root_pos_w_m = frame[F.ROOT_POS].copy()
        ref.root_quat_wxyz = F.matrix_to_quat(rot)
        ref.q_rad = frame[F.JOINTS].copy()
        # The tracker's velocity command: the plan's mean root velocity over up to one gait
        # cycle ahead, in the heading frame. Frame-to-frame differences carry the pelvis sway
        # (measured +-0.04 m/s sideways while standing), which a velocity-command policy takes
        # as a request to step; averaging over a cycle cancels it, and a small deadband keeps a
        # standing plan standing.
        m = min(len(self.plan), self.config.velocity_window_frames)
        ahead = self.plan[m - 1]
        span = (m - a) / self.config.fps
        vel_w = (ahead[F.ROOT_POS] - frame[F.ROOT_POS]) / max(span, 1e-3)
        yaw = float(F.yaw_of_matrix(rot))
        yaw_ahead = float(F.yaw_of_matrix(F.rot6d_to_matrix(ahead[F.ROOT_ROT])))
        wz = ((yaw_ahead - yaw + math.pi) % (2 * math.pi) - math.pi) / max(span, 1e-3)
        c, s = math.cos(yaw), math.sin(yaw)
        v = np.array([c * vel_w[0] + s * vel_w[1], -s * vel_w[0] + c * vel_w[1], 0.0])
        if math.hypot(v[0], v[1]) < self.config.velocity_deadband_mps:
            v[:2] = 0.0
        if abs(wz) < self.config.yaw_rate_deadband_radps:
            wz = 0.0
        ref.root_linvel_h_mps = v
        ref.root_angvel_h_radps = np.array([0.0, 0.0, wz])
        feet = frame[F.EFFECTORS].reshape(F.NUM_EFFECTORS, 3)[2:4]
        ref.contacts = feet[:, 2] < 0.034 + 0.025
        if self.skeleton.has_fingers:
            ref.hand_q_rad = frame[F.FINGERS].copy()
        ref.frame_targets_w = dict(self._frame_targets)
        ref.style = self._style
        ref.pelvis_height_m = self._last_cmd.pelvis_height_m if self._last_cmd is not None else None
        return ref
