"""GoalGenerator: the generator stage that executes task goals (types.TaskGoal) in a known scene.

Between goals the launch file's own generator runs (velocity, backbone, ...). A goal becomes a
sequence of phases, each a reference the tracking layer (trackers/layer.py) can follow:

  locomotion   walking with the policy to a stance near the work (velocity commands, closed on the
               robot's measured pose), then standing still until it has settled
  whole body   a WholeBodyTrajectory for the whole-body controller: footsteps (flat, turning, onto or
               off a platform), standing at a height, reaching, grasping, lifting, carrying and
               setting down a box, with the box's known forces on the hands

The first whole-body reference after walking starts at the measured configuration (the soles
where they are), so the hand-over does not jump; each later one starts where the previous ended.
Where the robot must be is planned from the scene (task knowledge: where the boxes, tables and
platforms are) and the robot's world pose: the simulator's ground truth in simulation (a stand-in
for a localisation system: on the robot, goals in world coordinates need one; without a world
pose a goal fails with that message).

Per goal: planned (`plan_cpu_s`), then `goal_status[goal_id]` = "reached" or "failed" with
`goal_messages[goal_id]` saying why. After a goal the robot stays under the whole-body
controller while it holds a box, stands on a platform, holds a reach or stands at a height the
walking policy cannot hold (below `policy_height_m[0]`); otherwise it stands up and hands back.
"""

from __future__ import annotations

import math
import time
from collections import deque
from collections.abc import Iterator
from dataclasses import dataclass, field

import numpy as np

from g1_control.generator.goals.box import (
    GRASP_DISTANCE_M,
    Approach,
    grasp_width,
    hand_forces,
    hand_points,
    pick_approach,
    place_target,
)
from g1_control.generator.goals.poses import PosePlanner, ReachRefused, flat_soles, stance_heading
from g1_control.generator.goals.stepping import (
    SOLE_HALF_LENGTH_M,
    Stance,
    SteppingConfig,
    level_steps,
    stepping_trajectory,
    walk_steps,
)
from g1_control.generator.styles import ROLLOUT_STYLES
from g1_control.generator.whole_body import WholeBodyTrajectory, keyframe_trajectory, smoothstep
from g1_control.interfaces import Generator
from g1_control.robot import g1
from g1_control.rotations import wrap_angle, yaw_of
from g1_control.scene import Block, Box, SceneConfig
from g1_control.types import (
    PHASE_LOCOMOTION,
    PHASE_WHOLE_BODY,
    Command,
    JointReference,
    KinematicReference,
    RobotState,
    TaskGoal,
)

REACHED, FAILED = "reached", "failed"
ARMS_BACK = g1.DEFAULT_Q_RAD.copy()
"""Stepping up to a table: the arms swung back (hand points ~5 cm ahead of the pelvis instead of
17 cm at table height), so the hands cannot catch the table's edge (it threw the robot over,
measured)."""
for _side in ("left", "right"):
    ARMS_BACK[g1.JOINT_INDEX[f"{_side}_shoulder_pitch_joint"]] = 0.6
    ARMS_BACK[g1.JOINT_INDEX[f"{_side}_elbow_joint"]] = 0.4
RAISE_AHEAD_M = 0.10
"""Hands rise (and come back) this far ahead of the pelvis, above the box, on their way to it."""
ARMS = np.array(g1.ARM_JOINTS)
GRAVITY = 9.81


class GoalFailed(RuntimeError):
    """A goal that cannot be done (the message says why)."""


@dataclass
class GoalConfig:
    walk_speed_mps: float = 0.4
    turn_rate_radps: float = 0.6
    approach_offset_m: float = 0.2
    """The walking policy stops this much short of a work stance; the whole-body controller steps
    the rest (the policy stops within ~5-10 cm; footsteps are exact)."""
    approach_tolerance_m: float = 0.08
    approach_heading_tolerance_rad: float = 0.12
    settle_s: float = 1.0
    """Standing still this long (speed below settle_speed_mps) before a hand-over."""
    settle_speed_mps: float = 0.05
    walk_timeout_s: float = 45.0
    stand_s: float = 1.0
    """After a hand-over: from the measured pose to a clean standing pose."""
    move_s: float = 2.0
    """Joint-space moves of the arms and the body (reach, height)."""
    reach_hold_s: float = 1.5
    squeeze_n: float = 20.0
    """Per hand: twice the Coulomb minimum for a 2 kg box at mu 1 (m g / 2 mu = 9.8 N)."""
    lift_m: float = 0.10
    pre_gap_m: float = 0.065
    press_m: float = 0.01
    """Hand targets this far inside the box's faces (the squeeze is the known force; this keeps contact)."""
    force_ramp_s: float = 0.4
    backup_m: float = 0.3
    """Steps back from a table before turning with a box."""
    carry: SteppingConfig = field(default_factory=lambda: SteppingConfig(
        max_advance_m=0.10, max_turn_rad=0.18, single_support_s=0.6, double_support_s=0.25))
    steps: SteppingConfig = field(default_factory=lambda: SteppingConfig(
        max_advance_m=0.08, max_side_m=0.06, single_support_s=0.5, double_support_s=0.2))
    """Stepping into a work stance (and onto a platform): short, unhurried steps (a 0.24 m diagonal
    step into a table's stance left the body behind and it fell, measured)."""
    toe_gap_m: float = 0.055
    """Stepping up: the toes stop this short of the platform's edge."""
    past_edge_m: float = 0.12
    """Stepping up: the sole's centre lands this far past the edge (the heel is 0.085 m behind it)."""
    clear_of_platform_m: float = 0.30
    """After stepping down, the stance's mid-point steps back to at least this far from the
    platform before the hand-back: the step down lands where the step up started (mid-point
    0.16 m from the edge), and the walking policy turning in place there put a sole centre 4 cm
    from the edge and the shin on the platform's top edge (measured: program 20 of g1 bench
    program, a fall). The walking policy knows nothing of the platform."""
    policy_height_m: tuple[float, float] = (0.63, 0.78)
    """Pelvis heights the walking policy holds (its envelope); others stand under the WBC."""
    height_min_m: float = 0.45
    plan_in_background: bool = False
    """Plan in a worker thread while the robot holds its current reference (wall-clock runs: a
    carry's footstep plan takes ~1-2 s of CPU, which would stall the loop). Off in lockstep, where
    planning inline keeps runs deterministic (simulated time waits for it)."""


@dataclass
class Held:
    box: Box
    forces: np.ndarray
    """(2, 3) hand forces while held (world axes at the time of the grasp's heading)."""


class GoalGenerator(Generator):
    """See the module docstring. inner: the launch file's generator, for everything but goals."""

    def __init__(self, inner: Generator, scene: SceneConfig, config: GoalConfig | None = None):
        self.inner = inner
        self.scene = scene
        self.config = config or GoalConfig()
        self.poses = PosePlanner()
        self.ik = self.poses.ik
        self.goal_status: dict[str, str] = {}
        self.goal_messages: dict[str, str] = {}
        self.plan_cpu_s: dict[str, float] = {}
        self.goal_info: dict[str, dict] = {}
        """Per goal, for judging it from outside: kind, start/end time, the hold window of a reach,
        its target in the world (reach point, box, where the box goes, platform)."""
        self.log: list[tuple[float, str]] = []
        self._ref = KinematicReference()
        self._joint = JointReference()
        self._pool = None
        if self.config.plan_in_background:
            import sys
            from concurrent.futures import ThreadPoolExecutor

            self._pool = ThreadPoolExecutor(max_workers=1, thread_name_prefix="goal-planner")
            # The planner and the control thread share the GIL: switch often, so a tick waits
            # at most ~1 ms for the planner's Python (default 5 ms).
            sys.setswitchinterval(min(sys.getswitchinterval(), 0.001))
        self.reset_state()

    # -- lifecycle ------------------------------------------------------------------------------
    def reset_state(self) -> None:
        self.phase = PHASE_LOCOMOTION
        self._queue: deque[TaskGoal] = deque()
        self._seen: set[str] = set()
        self._coro: Iterator[None] | None = None
        self._goal: TaskGoal | None = None
        self._plan: WholeBodyTrajectory | None = None
        self._plan_t0 = 0.0
        self._walk = np.zeros(3)
        self._held: Held | None = None
        self.on_platform: str | None = None
        self.box_positions: dict[str, np.ndarray | None] = {b.name: self.scene.box_center(b) for b in self.scene.boxes}
        self._height: float | None = None
        self._style = "default"
        self._overlay = None
        self._keep = False
        """Stay under the whole-body controller after the plan ends (a reach holds its point)."""
        self._step_back = (0.0, 0.0)
        self._t = 0.0
        self._state: RobotState | None = None
        self._command = Command()

    def reset(self, state: RobotState) -> None:
        self.reset_state()
        self.inner.reset(state)

    @property
    def busy(self) -> bool:
        return self._coro is not None or bool(self._queue)

    @property
    def holding(self) -> str | None:
        return self._held.box.name if self._held else None

    # -- the tick ---------------------------------------------------------------------------------
    def update(self, command: Command, state: RobotState) -> KinematicReference:
        self._state, self._command, self._t = state, command, state.t_s
        for goal in command.tasks:
            if goal.goal_id not in self._seen:
                self._seen.add(goal.goal_id)
                self._queue.append(goal)
        if self._coro is None:
            if self._queue:
                self._goal = self._queue.popleft()
                self._coro = self._run_goal(self._goal)
            else:
                self._coro = self._idle(command)
        if self._coro is not None:
            try:
                next(self._coro)
            except StopIteration:
                self._coro = None
        return self._reference(command, state)

    def _reference(self, command: Command, state: RobotState) -> KinematicReference:
        if self.phase == PHASE_WHOLE_BODY:
            assert self._plan is not None
            j = self._plan.sample(self._t - self._plan_t0, self._joint)
            if self._overlay is not None:
                style, t0 = self._overlay
                q_now, q_next = style.pose(self._t - t0), style.pose(self._t - t0 + 0.01)
                j.q_rad[ARMS] = q_now[ARMS]
                j.dq_radps[ARMS] = (q_next[ARMS] - q_now[ARMS]) / 0.01
            ref = self._ref.set_from(j)
            ref.upper_body_override = True
            ref.pelvis_height_m = None
            ref.style = command.style
            return ref
        if self._coro is not None and self._goal is not None:
            walk = Command(vx_mps=float(self._walk[0]), vy_mps=float(self._walk[1]), wz_radps=float(self._walk[2]))
            ref = self.inner.update(walk, state)
        else:
            ref = self.inner.update(command, state)
        ref.phase = PHASE_LOCOMOTION
        return ref

    def joint_reference(self, t_s: float) -> JointReference:
        """The whole-body reference of this tick (with joint velocities and hand forces)."""
        return self._joint

    # -- goals --------------------------------------------------------------------------------------
    def _run_goal(self, goal: TaskGoal) -> Iterator[None]:
        gid = goal.goal_id
        self._note(f"goal {gid}: {goal.describe()}")
        self._info = self.goal_info.setdefault(gid, {"kind": goal.kind, "describe": goal.describe(), "start_s": self._t})
        try:
            if self._state is None or self._state.base_pos_w_m is None:
                raise GoalFailed("no world pose for the robot (goals in world coordinates need localisation; "
                                 "the simulator gives it)")
            run = {"reach": self._reach, "pick": self._pick, "place": self._place, "step_up": self._step_up,
                   "step_down": self._step_down}[goal.kind]
            yield from run(goal)
            self.goal_status[gid] = REACHED
            self._note(f"goal {gid}: reached")
        except (GoalFailed, ReachRefused) as exc:
            self.goal_status[gid] = FAILED
            self.goal_messages[gid] = str(exc)
            self._note(f"goal {gid}: failed: {exc}")
            if self.phase == PHASE_WHOLE_BODY and self._plan is None:
                self.phase = PHASE_LOCOMOTION
        self._walk[:] = 0.0
        self._goal = None
        self._info["end_s"] = self._t
        self._info["status"] = self.goal_status.get(gid)

    def _note(self, text: str) -> None:
        self.log.append((self._t, text))

    # -- idle: heights the policy cannot hold, handing back -----------------------------------------
    def _idle(self, command: Command) -> Iterator[None] | None:
        cfg = self.config
        height = command.pelvis_height_m
        moving = abs(command.vx_mps) > 0.02 or abs(command.vy_mps) > 0.02 or abs(command.wz_radps) > 0.02
        low = height is not None and height < cfg.policy_height_m[0] - 1e-3 and not moving
        if low:
            assert height is not None
            h = max(height, cfg.height_min_m)
            if self.phase != PHASE_WHOLE_BODY or self._height is None or abs(h - self._height) > 2e-3 \
                    or command.style != self._style:
                return self._stand_at(h, command.style)
            return None
        if self.phase == PHASE_WHOLE_BODY and self._held is None and self.on_platform is None \
                and self._plan is not None and self._t - self._plan_t0 >= self._plan.duration_s \
                and (moving or not self._keep or self._height is not None):
            return self._hand_back()
        return None

    def _stand_at(self, height: float, style_name: str) -> Iterator[None]:
        style = ROLLOUT_STYLES.get(style_name) or ROLLOUT_STYLES["default"]
        if self.phase != PHASE_WHOLE_BODY:
            yield from self._enter_whole_body()
        q0 = self._hold_q()
        soles = flat_soles(self.ik, q0)
        ground = min(s[0][2] for s in soles)
        mean_pose = np.mean([style.pose(t) for t in np.linspace(0.0, 5.0, 26)], axis=0) if style.wave_hz else style.pose(0.0)
        q_goal = yield from self._compute(f"height {height:.2f}", lambda: self.poses.stand(
            q0, soles, ground + height, mean_pose))
        duration = self.config.move_s * max(1.0, abs(q_goal[2] - q0[2]) / 0.15)
        self._height, self._style = height, style_name
        yield from self._run(keyframe_trajectory("height", [(0.0, q0), (duration, q_goal)]), keep=True)
        if style.wave_hz:
            self._overlay = (style, self._t - duration)  # type: ignore[assignment]  # declared None at start

    def _hand_back(self) -> Iterator[None]:
        """Stand up with the default arms and hand over to the walking policy."""
        q0 = self._hold_q()
        soles = flat_soles(self.ik, q0)
        ground = min(s[0][2] for s in soles)
        q_goal = yield from self._compute("stand up", lambda: self.poses.stand(
            q0, soles, ground + self.poses.nominal_pelvis_m, g1.DEFAULT_Q_RAD))
        duration = self.config.move_s * max(0.6, abs(q_goal[2] - q0[2]) / 0.15)
        yield from self._run(keyframe_trajectory("stand", [(0.0, q0), (duration, q_goal)]))
        self._note("hand back to the walking policy")
        self.phase = PHASE_LOCOMOTION
        self._plan = None
        self._height = None
        self._overlay = None
        assert self._state is not None
        self.inner.reset(self._state)

    # -- phases -------------------------------------------------------------------------------------
    def _measured_q(self) -> np.ndarray:
        """The robot's configuration now (pinocchio q): joints, IMU orientation, world position."""
        s = self._state
        assert s is not None and s.base_pos_w_m is not None
        w, x, y, z = s.imu_quat_wxyz
        return np.concatenate([s.base_pos_w_m, [x, y, z, w], s.q_rad])

    def _hold_q(self) -> np.ndarray:
        """Where the whole-body reference is now (the end of the current plan)."""
        assert self._plan is not None
        j = self._plan.sample(min(self._t - self._plan_t0, self._plan.duration_s))
        w, x, y, z = j.root_quat_wxyz
        q = np.concatenate([j.root_pos_w_m, [x, y, z, w], j.q_rad])
        if self._overlay is not None:
            q[7 + ARMS] = self._overlay[0].pose(self._t - self._overlay[1])[ARMS]
        return q

    def _offset(self) -> np.ndarray:
        """Plan frame minus world (xy): the tracker's odometry drift, measured against the world pose."""
        if self.phase != PHASE_WHOLE_BODY or self._plan is None or self._state is None:
            return np.zeros(2)
        j = self._plan.sample(min(self._t - self._plan_t0, self._plan.duration_s))
        assert self._state.base_pos_w_m is not None
        return j.root_pos_w_m[:2] - self._state.base_pos_w_m[:2]

    def _run(self, traj: WholeBodyTrajectory, keep: bool = False) -> Iterator[None]:
        self._plan, self._plan_t0 = traj, self._t
        self._overlay = None
        self._keep = keep
        self.phase = PHASE_WHOLE_BODY
        while self._t - self._plan_t0 < traj.duration_s:
            yield

    def _enter_whole_body(self) -> Iterator[None]:
        """From walking: a reference from the measured pose to a clean standing one."""
        q = self._measured_q()
        soles = flat_soles(self.ik, q)
        ground = [self.scene.ground_height(p[:2]) for p, _ in soles]
        lift = min(p[2] - g for (p, _), g in zip(soles, ground))
        q[2] -= lift  # the lower sole exactly on its ground
        soles = [(np.array([p[0], p[1], g]), r) for (p, r), g in zip(soles, ground)]
        q_stand = yield from self._compute("stand", lambda: self.poses.stand(
            q, soles, min(ground) + self.poses.nominal_pelvis_m, g1.DEFAULT_Q_RAD))
        self._note("hand over to the whole-body controller")
        yield from self._run(keyframe_trajectory("stand", [(0.0, q), (self.config.stand_s, q_stand)]))

    def _walk_to(self, approach: Approach, *, out_m: float) -> Iterator[None]:
        """Walk (the policy) to `out_m` short of the approach stance, facing it, then stand still."""
        cfg = self.config
        fwd = np.array([math.cos(approach.heading), math.sin(approach.heading)])
        goal_xy = approach.pelvis_xy() - out_m * fwd
        t0 = self._t
        settled_since: float | None = None
        while True:
            s = self._state
            assert s is not None and s.base_pos_w_m is not None
            if self._t - t0 > cfg.walk_timeout_s:
                raise GoalFailed(f"did not reach the stance within {cfg.walk_timeout_s:.0f} s")
            yaw = yaw_of(s.imu_quat_wxyz)
            d = goal_xy - s.base_pos_w_m[:2]
            dist = float(np.hypot(*d))
            yaw_err = float(wrap_angle(approach.heading - yaw))
            c, sn = math.cos(yaw), math.sin(yaw)
            d_h = np.array([c * d[0] + sn * d[1], -sn * d[0] + c * d[1]])
            if dist <= cfg.approach_tolerance_m and abs(yaw_err) <= cfg.approach_heading_tolerance_rad:
                self._walk[:] = 0.0
                speed = float(np.hypot(*s.base_linvel_w_mps[:2])) if s.base_linvel_w_mps is not None else 0.0
                settled_since = self._t if settled_since is None or speed > cfg.settle_speed_mps else settled_since
                if self._t - settled_since >= cfg.settle_s:
                    return
                yield
                continue
            settled_since = None
            if dist > 0.5:
                bearing_err = float(wrap_angle(math.atan2(d[1], d[0]) - yaw))
                vx = min(cfg.walk_speed_mps, 0.8 * dist) * max(0.0, math.cos(bearing_err)) ** 2
                self._walk[:] = (vx, 0.0, float(np.clip(1.5 * bearing_err, -cfg.turn_rate_radps, cfg.turn_rate_radps)))
            else:
                v = np.clip(1.2 * d_h, -0.25, 0.25)
                v[np.abs(d_h) < 0.02] = 0.0
                v = np.where((v != 0) & (np.abs(v) < 0.1), np.sign(v) * 0.1, v)
                wz = float(np.clip(1.5 * yaw_err, -cfg.turn_rate_radps, cfg.turn_rate_radps))
                if 0 < abs(wz) < 0.15 and abs(yaw_err) > cfg.approach_heading_tolerance_rad * 0.5:
                    wz = math.copysign(0.15, wz)
                self._walk[:] = (v[0], v[1], wz)
            yield

    def _step_to(self, mid_xy: np.ndarray, heading: float, cfg: SteppingConfig, *, posture=None, forces=None,
                 com_shift=None, first_back_m: float = 0.0, name: str = "steps") -> Iterator[None]:
        q0 = self._hold_q()
        stance = Stance.of(self.ik, q0)
        ground = self.scene.ground_height
        steps = []
        if first_back_m > 0:
            back = stance.mid_xy - first_back_m * np.array([math.cos(stance.heading), math.sin(stance.heading)])
            steps += walk_steps(stance, back, stance.heading, cfg, lambda xy: ground(xy), backward_max_m=1.0)
            for st in steps:
                stance = stance.apply(st)
        steps += walk_steps(stance, mid_xy, heading, cfg, lambda xy: ground(xy), then=steps)
        if not steps:
            return
        plan = yield from self._compute(name, lambda: stepping_trajectory(
            self.ik, q0, steps, cfg, posture=posture, hand_forces=forces, com_offset_h_m=com_shift, name=name))
        self.last_steps = plan
        if plan.sole_error_m > 0.03:
            raise GoalFailed(f"{name}: the footsteps are out of the legs' reach (plan off by "
                             f"{plan.sole_error_m * 100:.0f} cm)")
        yield from self._run(plan.trajectory)

    def _correct_stance(self, mid_w: np.ndarray, heading: float, cfg: SteppingConfig, *, posture=None,
                        forces=None, com_shift=None, tolerance_m: float = 0.03, rounds: int = 2) -> Iterator[None]:
        """Small steps until the stance is where it should be in the world (the tracker's odometry
        drifts a few cm per metre walked; the world pose says where the robot really is)."""
        for _ in range(rounds):
            q0 = self._hold_q()
            stance = Stance.of(self.ik, q0)
            mid_plan = mid_w + self._offset()
            err = float(np.hypot(*(mid_plan - stance.mid_xy)))
            if err <= tolerance_m and abs(wrap_angle(heading - stance.heading)) <= 0.05:
                return
            self._note(f"stance {err * 100:.0f} cm off: correcting steps")
            yield from self._step_to(mid_plan, heading, cfg, posture=posture, forces=forces, com_shift=com_shift,
                                     name="correction")

    def _compute(self, what: str, fn):
        """fn() inline, or in the planner thread while the loop keeps ticking (the robot holds its
        reference meanwhile); returns its result (use with `yield from`). Records the planning CPU
        (inline) or wall time (background) under `what`."""
        if self._pool is None:
            t0 = time.process_time()
            out = fn()
            self._cpu(what, t0)
            return out
        start = time.perf_counter()
        future = self._pool.submit(fn)
        while not future.done():
            yield
        key = f"{self._goal.goal_id if self._goal else ''} {what} (background, wall)".strip()
        self.plan_cpu_s[key] = self.plan_cpu_s.get(key, 0.0) + time.perf_counter() - start
        return future.result()

    def _cpu(self, what: str, t0: float) -> None:
        key = f"{self._goal.goal_id if self._goal else ''} {what}".strip()
        self.plan_cpu_s[key] = self.plan_cpu_s.get(key, 0.0) + time.process_time() - t0

    # -- reach -------------------------------------------------------------------------------------
    def _reach(self, goal: TaskGoal) -> Iterator[None]:
        cfg = self.config
        if self.phase != PHASE_WHOLE_BODY:
            yield from self._enter_whole_body()
        q0 = self._hold_q()
        soles = flat_soles(self.ik, q0)
        heading = stance_heading(soles)
        off = np.append(self._offset(), 0.0)
        if goal.pos_w_m is not None:
            target = np.asarray(goal.pos_w_m, dtype=float) + off
        else:
            assert goal.offset_h_m is not None
            standing = q0.copy()  # the hand's standing position: arms at the default pose
            standing[7 + ARMS] = g1.DEFAULT_Q_RAD[ARMS]
            base = self.poses.hand_point(standing, 0 if goal.hand == "left" else 1)
            c, s = math.cos(heading), math.sin(heading)
            o = goal.offset_h_m
            target = base + np.array([c * o[0] - s * o[1], s * o[0] + c * o[1], o[2]])
        def solve():
            if goal.hand == "both":
                lateral = np.array([-math.sin(heading), math.cos(heading), 0.0])
                res = self.poses.hands_on(q0, soles, (target + 0.1 * lateral, target - 0.1 * lateral), heading)
                if res.residual_m > 0.03:
                    raise ReachRefused(f"both hands: the closest pose leaves a hand {res.residual_m * 100:.1f} cm off")
                return res
            return self.poses.reach(q0, soles, 0 if goal.hand == "left" else 1, target)

        res = yield from self._compute("reach", solve)
        self._note(f"reach: {res.mode}, hand {res.residual_m * 100:.1f} cm from the point in the plan")
        move = cfg.move_s * max(1.0, float(np.abs(res.q[7:] - q0[7:]).max()) / 1.5)
        self._info.update(hand=goal.hand, target_w_m=(target - off).tolist(), mode=res.mode,
                          plan_residual_m=res.residual_m, hold_s=(self._t + move, self._t + move + cfg.reach_hold_s))
        yield from self._run(keyframe_trajectory("reach", [(0.0, q0), (move, res.q), (move + cfg.reach_hold_s, res.q)]),
                             keep=True)

    # -- boxes ---------------------------------------------------------------------------------------
    def _box(self, name: str | None) -> Box:
        if name is not None:
            box = self.scene.box(name)
            if box is None:
                raise GoalFailed(f"'{name}' is not a box of the scene")
            return box
        s = self._state
        assert s is not None and s.base_pos_w_m is not None
        yaw = yaw_of(s.imu_quat_wxyz)
        fwd = np.array([math.cos(yaw), math.sin(yaw)])
        best, score = None, math.inf
        for b in self.scene.boxes:
            pos = self.box_positions.get(b.name)
            if pos is None:
                continue
            d = pos[:2] - s.base_pos_w_m[:2]
            dist = float(np.hypot(*d))
            if dist > 4.0 or d @ fwd < 0.3 * dist:  # in front: within ~70 degrees of the heading
                continue
            if dist < score:
                best, score = b, dist
        if best is None:
            raise GoalFailed("no box in front of the robot (within 4 m, 70 degrees of its heading)")
        return best

    def _pick(self, goal: TaskGoal) -> Iterator[None]:
        cfg = self.config
        if self._held is not None:
            raise GoalFailed(f"already holding '{self._held.box.name}'")
        box = self._box(goal.object)
        center = self.box_positions.get(box.name)
        if center is None:
            raise GoalFailed(f"box '{box.name}' is held")
        s = self._state
        assert s is not None and s.base_pos_w_m is not None
        approach = pick_approach(self.scene, box, center[:2], s.base_pos_w_m[:2])
        if self.phase != PHASE_WHOLE_BODY:
            yield from self._walk_to(approach, out_m=cfg.approach_offset_m)
            yield from self._enter_whole_body()
        off = self._offset()
        yield from self._step_to(approach.mid_xy + off, approach.heading, cfg.steps, name="approach",
                                 posture=ARMS_BACK)
        yield from self._correct_stance(approach.mid_xy, approach.heading, cfg.steps, posture=ARMS_BACK)
        # the grasp, from the stance the steps ended in
        q0 = self._hold_q()
        soles = flat_soles(self.ik, q0)
        heading = stance_heading(soles)
        c = center + np.append(self._offset(), 0.0)
        width = grasp_width(box, heading)
        weight = box.mass_kg * GRAVITY
        # the hands rise close to the body first (a table's edge is ~0.22 m ahead of the pelvis:
        # moving them straight to the box dragged them over the table top, measured)
        via = hand_points(c, heading, width, cfg.pre_gap_m + 0.03, dz_m=0.08, ahead_m=-(GRASP_DISTANCE_M - RAISE_AHEAD_M))
        pre = hand_points(c, heading, width, cfg.pre_gap_m)
        con = hand_points(c, heading, width, -cfg.press_m)
        lift = hand_points(c, heading, width, -cfg.press_m, dz_m=cfg.lift_m)
        shift = np.array([-box.mass_kg / self.poses.mass_kg * GRASP_DISTANCE_M, 0.0])
        def solve():
            poses = []
            q = q0
            for name, targets, com_shift in (("via", via, None), ("pre-grasp", pre, None), ("contact", con, None),
                                              ("lift", lift, shift)):
                res = self.poses.hands_on(q, soles, targets, heading, com_shift)
                if res.residual_m > 0.01:  # a poor warm start (the pose before): again from the stance
                    again = self.poses.hands_on(q0, soles, targets, heading, com_shift)
                    res = again if again.residual_m < res.residual_m else res
                if res.residual_m > 0.03 and name != "via":
                    raise ReachRefused(f"box '{box.name}': the hands get only within {res.residual_m * 100:.1f} cm "
                                       f"of the {name} points (out of reach)")
                q = res.q
                poses.append(q)
            return poses

        q_via, q_pre, q_con, q_lift = yield from self._compute("grasp", solve)
        t = {"via": 1.2, "pre": 2.2, "con": 3.0, "squeeze": 3.5, "lift": 4.7, "end": 5.7}
        full = hand_forces(heading, cfg.squeeze_n, weight)
        squeeze_only = hand_forces(heading, cfg.squeeze_n, 0.0)

        def forces(tk: float) -> np.ndarray:
            a = float(smoothstep((tk - t["con"] + 0.1) / (t["squeeze"] - t["con"] + 0.1)))
            b = float(smoothstep((tk - t["squeeze"]) / cfg.force_ramp_s))
            return a * squeeze_only + b * (full - squeeze_only)

        keys = [(0.0, q0), (t["via"], q_via), (t["pre"], q_pre), (t["con"], q_con), (t["squeeze"], q_con),
                (t["lift"], q_lift), (t["end"], q_lift)]
        self._info.update(box=box.name, box_start_w_m=center.tolist(), lift_m=cfg.lift_m,
                          held_from_s=self._t + t["lift"])
        yield from self._run(keyframe_trajectory("pick", keys, hand_forces=forces))
        self._held = Held(box, full)
        self.box_positions[box.name] = None

    def _place(self, goal: TaskGoal) -> Iterator[None]:
        cfg = self.config
        if self._held is None:
            raise GoalFailed("holding no box")
        box = self._held.box
        if goal.object is not None and goal.object != box.name:
            raise GoalFailed(f"holding '{box.name}', not '{goal.object}'")
        s = self._state
        assert s is not None and s.base_pos_w_m is not None
        target, point = goal.target, goal.pos_w_m
        if target is not None and self.scene.block(target) is None and point is not None:
            target = None  # a place the scene does not have as a table or platform: its point
        if target is None and point is None:  # "put it down in front": a table there, else the floor
            yaw = yaw_of(s.imu_quat_wxyz)
            ahead = s.base_pos_w_m[:2] + GRASP_DISTANCE_M * np.array([math.cos(yaw), math.sin(yaw)])
            near = [b for b in (*self.scene.tables, *self.scene.platforms) if b.distance_xy(ahead) < 0.35]
            if near:
                target = min(near, key=lambda b: b.distance_xy(ahead)).name
            else:
                point = np.array([ahead[0], ahead[1], box.size[2] / 2])
        center_w, approach = place_target(self.scene, box, target, point, s.base_pos_w_m[:2])
        self._info.update(box=box.name, target_w_m=center_w.tolist())
        q0 = self._hold_q()
        posture = q0[7:].copy()
        weight = box.mass_kg * GRAVITY
        shift = np.array([-box.mass_kg / self.poses.mass_kg * GRASP_DISTANCE_M, 0.0])
        stance = Stance.of(self.ik, q0)
        far = float(np.hypot(*(approach.mid_xy - stance.mid_xy))) > 0.05 or \
            abs(wrap_angle(approach.heading - stance.heading)) > 0.05
        if far:
            off = self._offset()
            # carry: the hand forces turn with the robot, so plan them per heading: held constant in
            # the robot's frame (the squeeze across it, the weight down)
            yield from self._carry(approach.mid_xy + off, approach.heading, posture, weight, shift)
            yield from self._correct_stance(approach.mid_xy, approach.heading, cfg.carry, posture=posture,
                                            forces=hand_forces(approach.heading, cfg.squeeze_n, weight),
                                            com_shift=self.poses.com_offset_m + shift)
        q0 = self._hold_q()
        soles = flat_soles(self.ik, q0)
        heading = stance_heading(soles)
        c = center_w + np.append(self._offset(), 0.0)
        width = grasp_width(box, heading)
        down = hand_points(c, heading, width, -cfg.press_m, dz_m=0.005)
        opened = hand_points(c, heading, width, cfg.pre_gap_m, dz_m=0.005)
        out = hand_points(c, heading, width, cfg.pre_gap_m + 0.03, dz_m=0.08, ahead_m=-(GRASP_DISTANCE_M - RAISE_AHEAD_M))
        def solve():
            down_pose = self.poses.hands_on(q0, soles, down, heading, shift)
            if down_pose.residual_m > 0.03:
                raise ReachRefused(f"the hands get only within {down_pose.residual_m * 100:.1f} cm of where the box "
                                   "goes (out of reach)")
            q_open = self.poses.hands_on(down_pose.q, soles, opened, heading).q
            q_out = self.poses.hands_on(q_open, soles, out, heading).q
            ground = min(p[2] for p, _ in soles)
            return down_pose, q_open, q_out, self.poses.stand(q_out, soles, ground + self.poses.nominal_pelvis_m,
                                                              g1.DEFAULT_Q_RAD)

        q_down, q_open, q_out, q_stand = yield from self._compute("release", solve)
        t = {"down": 1.5, "release": 2.2, "open": 3.0, "out": 4.0, "stand": 5.5, "end": 6.0}
        full = hand_forces(heading, cfg.squeeze_n, weight)
        squeeze_only = hand_forces(heading, cfg.squeeze_n, 0.0)

        def forces(tk: float) -> np.ndarray:
            b = 1.0 - float(smoothstep((tk - t["down"] + cfg.force_ramp_s) / cfg.force_ramp_s))
            a = 1.0 - float(smoothstep((tk - t["down"]) / (t["release"] - t["down"])))
            return a * squeeze_only + b * (full - squeeze_only)

        keys = [(0.0, q0), (t["down"], q_down.q), (t["release"], q_down.q), (t["open"], q_open), (t["out"], q_out),
                (t["stand"], q_stand), (t["end"], q_stand)]
        yield from self._run(keyframe_trajectory("place", keys, hand_forces=forces))
        self._info["released_s"] = self._t - t["end"] + t["release"]
        self._held = None
        self.box_positions[box.name] = center_w
        if self.on_platform is None:
            yield from self._hand_back()

    def _carry(self, mid_xy: np.ndarray, heading: float, posture: np.ndarray, weight: float,
               com_shift: np.ndarray) -> Iterator[None]:
        """Footsteps to a stance with the box held: back up from the table, turn, walk, turn; the
        hand forces follow the robot's heading along the way."""
        cfg = self.config
        q0 = self._hold_q()
        stance = Stance.of(self.ik, q0)
        back = stance.mid_xy - cfg.backup_m * np.array([math.cos(stance.heading), math.sin(stance.heading)])
        ground = self.scene.ground_height
        steps = walk_steps(stance, back, stance.heading, cfg.carry, lambda xy: ground(xy), backward_max_m=1.0)
        for st in steps:
            stance = stance.apply(st)
        steps += walk_steps(stance, mid_xy, heading, cfg.carry, lambda xy: ground(xy), then=steps)
        forces = hand_forces(stance_heading(flat_soles(self.ik, q0)), cfg.squeeze_n, weight)
        plan = yield from self._compute("carry", lambda: stepping_trajectory(
            self.ik, q0, steps, cfg.carry, posture=posture, hand_forces=forces,
            com_offset_h_m=self.poses.com_offset_m + com_shift, name="carry"))
        self.last_steps = plan
        traj = plan.trajectory
        # hand forces per sample, turned with the pelvis's heading
        yaws = traj.root_rpy_rad[:, 2]
        traj.hand_forces_w_n = np.array([hand_forces(y, cfg.squeeze_n, weight) for y in yaws])
        if plan.sole_error_m > 0.03:
            raise GoalFailed(f"carry: the footsteps are out of the legs' reach (plan off by "
                             f"{plan.sole_error_m * 100:.0f} cm)")
        yield from self._run(traj)

    # -- platforms ------------------------------------------------------------------------------------
    def _platform(self, name: str | None):
        if name is not None:
            block = self.scene.block(name)
            if block is None or block not in self.scene.platforms:
                raise GoalFailed(f"'{name}' is not a platform of the scene")
            return block
        s = self._state
        assert s is not None and s.base_pos_w_m is not None
        here = s.base_pos_w_m[:2]
        best = min(self.scene.platforms, key=lambda p: p.distance_xy(here), default=None)
        if best is None or best.distance_xy(here) > 4.0:
            raise GoalFailed("no platform within 4 m")
        return best

    def _step_up(self, goal: TaskGoal) -> Iterator[None]:
        cfg = self.config
        if self.on_platform is not None:
            raise GoalFailed(f"already on '{self.on_platform}'")
        block = self._platform(goal.target)
        s = self._state
        assert s is not None and s.base_pos_w_m is not None
        # the side facing the robot; the robot squarely in front of it, clear of its corners
        local = block.local_xy(s.base_pos_w_m[:2])
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
        if block.half[axis] * 2 < cfg.past_edge_m + SOLE_HALF_LENGTH_M + 0.05:
            raise GoalFailed(f"platform '{block.name}' is too shallow to stand on")
        mid = edge + normal * (SOLE_HALF_LENGTH_M + cfg.toe_gap_m)
        heading = math.atan2(-normal[1], -normal[0])
        self._info.update(platform=block.name, height_m=block.height_m)
        approach = Approach(mid, heading)
        if self.phase != PHASE_WHOLE_BODY:
            yield from self._walk_to(approach, out_m=cfg.approach_offset_m)
            yield from self._enter_whole_body()
        yield from self._step_to(mid + self._offset(), heading, cfg.steps, name="approach")
        yield from self._correct_stance(mid, heading, cfg.steps, tolerance_m=0.02)
        q0 = self._hold_q()
        stance = Stance.of(self.ik, q0)
        forward = SOLE_HALF_LENGTH_M + cfg.toe_gap_m + cfg.past_edge_m
        steps = level_steps(stance, forward, block.height_m, cfg.steps)
        plan = yield from self._compute("step up", lambda: stepping_trajectory(self.ik, q0, steps, cfg.steps,
                                                                             name="step up"))
        yield from self._run(plan.trajectory)
        self.on_platform = block.name
        self._step_back = (forward, 0.0)

    def _step_down(self, goal: TaskGoal) -> Iterator[None]:
        cfg = self.config
        if self.on_platform is None:
            raise GoalFailed("not standing on a platform")
        self._info.update(platform=self.on_platform)
        forward, _ = self._step_back
        q0 = self._hold_q()
        stance = Stance.of(self.ik, q0)
        back = stance.mid_xy - forward * np.array([math.cos(stance.heading), math.sin(stance.heading)])
        level = self.scene.ground_height(back - self._offset())
        if level > 0.0:
            level = 0.0
        steps = level_steps(stance, -forward, level, cfg.steps)
        plan = yield from self._compute("step down", lambda: stepping_trajectory(self.ik, q0, steps, cfg.steps,
                                                                               name="step down"))
        yield from self._run(plan.trajectory)
        block = self.scene.block(self.on_platform)
        self.on_platform = None
        if block is not None:
            yield from self._clear_of(block)
        yield from self._hand_back()

    def _clear_of(self, block: Block) -> Iterator[None]:
        """Step straight back until the stance's mid-point is `clear_of_platform_m` from `block`."""
        cfg = self.config
        stance = Stance.of(self.ik, self._hold_q())
        gap = block.distance_xy(stance.mid_xy - self._offset())
        back_m = cfg.clear_of_platform_m - gap
        if back_m < 0.01:
            return
        self._note(f"{gap * 100:.0f} cm from '{block.name}': stepping {back_m * 100:.0f} cm back clear of it")
        back = stance.mid_xy - back_m * np.array([math.cos(stance.heading), math.sin(stance.heading)])
        yield from self._step_to(back, stance.heading, cfg.steps, name="clear of the platform", first_back_m=back_m)


__all__ = ["FAILED", "REACHED", "GoalConfig", "GoalFailed", "GoalGenerator"]
