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
replaced by interpolation toward the keyframe (counted in `fallbacks`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from g1_control.generator import features as F
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
    def __init__(self, inbetweener: Inbetweener, styles: dict[str, StyleStats], config: RuntimeConfig | None = None):
        self.model = inbetweener
        self.styles = styles
        self.config = config or RuntimeConfig()
        self.stats = PlanStats()
        self.ref = KinematicReference()
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
        frame = F.fix_effectors(frame[None])[0]
        self.history = np.repeat(frame[None], CONTEXT_FRAMES, axis=0)
        self.plan = frame[None].copy()
        self.plan_t0 = state.t_s
        self._t = state.t_s
        self._last_cmd = None
        self._object = None
        self.stats = PlanStats()

    # ------------------------------------------------------------------ planning
    def _root_state(self) -> RootState:
        h = self.history
        last, prev = h[-1], h[-2]
        yaw = float(F.yaw_of_matrix(F.rot6d_to_matrix(last[F.ROOT_ROT])))
        yaw_prev = float(F.yaw_of_matrix(F.rot6d_to_matrix(prev[F.ROOT_ROT])))
        rate = ((yaw - yaw_prev + math.pi) % (2 * math.pi) - math.pi) * self.config.fps
        return RootState(last[0:2].copy(), (last[0:2] - prev[0:2]) * self.config.fps, yaw, rate)

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
        for goal in command.goals:
            if goal.frame in OBJECT_GOALS:
                continue
            targets[goal.frame] = np.concatenate([np.asarray(goal.pos_w_m, float), [1.0, 0.0, 0.0, 0.0]])
        for name, pose7 in targets.items():
            if name in F.EFFECTOR_BODIES:
                k = F.EFFECTOR_BODIES.index(name)
                values[38 + 3 * k:41 + 3 * k] = pose7[:3]
                given[38 + 3 * k:41 + 3 * k] = True
        return Keyframe(values, given, gap, style, targets)

    def _replan(self, command: Command, reason: str) -> None:
        cfg = self.config
        key = self.keyframe(command)
        context = self.history[-CONTEXT_FRAMES:]
        origin, yaw = F.reference_of(context[-1])
        ctx_c = F.transform(context[None], origin, yaw)
        tgt_c = F.transform(key.values[None, None], origin, yaw)[:, 0]
        frames_c = self.model.infill(ctx_c, tgt_c, key.given[None], key.gap, np.array([style_id(key.style)]))
        frames = F.transform(frames_c, origin, yaw, inverse=True)[0]
        frames = self._stabilize(frames, key)
        # cross-fade: the old plan's frames still ahead (same times) blend into the new plan
        old = self.plan
        n = min(cfg.crossfade_frames, len(old), len(frames))
        if n:
            w = (np.arange(1, n + 1) / (n + 1))[:, None]
            frames[:n] = (1 - w) * old[:n] + w * frames[:n]
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
        frames[:, F.JOINTS] = np.clip(frames[:, F.JOINTS], g1.Q_MIN_RAD, g1.Q_MAX_RAD)
        frames[:, _WAIST_LEAN] = np.clip(frames[:, _WAIST_LEAN], -cfg.max_waist_lean_rad, cfg.max_waist_lean_rad)
        lo, _, hi = self._style_stats(key.style).pelvis_height_m
        floor = min(lo, key.values[2]) - cfg.height_margin_m
        ceil = max(hi, key.values[2]) + cfg.height_margin_m
        frames[:, 2] = np.clip(frames[:, 2], floor, ceil)
        rot = F.rot6d_to_matrix(frames[:, F.ROOT_ROT])
        tilt = np.arccos(np.clip(rot[:, 2, 2], -1.0, 1.0))
        if np.any(tilt > cfg.max_tilt_rad):
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
        feet = frame[F.EFFECTORS].reshape(4, 3)[2:]
        ref.contacts = feet[:, 2] < 0.034 + 0.025
        ref.frame_targets_w = dict(self._frame_targets)
        ref.style = self._style
        ref.pelvis_height_m = self._last_cmd.pelvis_height_m if self._last_cmd is not None else None
        return ref
