"""GoalGenerator: the generator stage that executes task goals (types.TaskGoal) in a known scene.

Between goals the launch file's own generator runs (velocity, backbone, ...). A goal becomes a
sequence of phases, each a reference the tracking layer (trackers/layer.py) can follow:

  locomotion   walking with the policy to a stance near the work (velocity commands, closed on the
               robot's measured pose), then standing still until it has settled; these commands go
               through a velocity generator (`walker`) whatever the launch file's generator: a
               planning generator (backbone) lags and overshoots small corrections, and the closed
               loop then sways around the stance (measured: +-0.2 m sidesteps for 45 s)
  whole body   a WholeBodyTrajectory for the whole-body controller: footsteps (flat, turning, onto or
               off a platform), standing at a height, reaching, grasping, lifting, carrying and
               setting down a box, with the box's known forces on the hands

The first whole-body reference after walking starts at the measured configuration (the soles
where they are), so the hand-over does not jump; each later one starts where the previous ended.
Where the robot must be is planned from the scene (task knowledge: where the boxes, tables and
platforms are) and the robot's world pose: the simulator's ground truth in simulation, or the
robot's own estimate (steer_by: leg odometry, fused with an external pose; always on a robot). Goals that need no world (a reach relative to the robot, heights) are
planned in the frame of the stance the robot stands in and run without one; a goal that does need
one fails at its start, before anything moves, saying why (context.world_pose_needed).

Per goal: planned (`plan_cpu_s`), then `goal_status[goal_id]` = "reached" or "failed" with
`goal_messages[goal_id]` saying why. After a goal the robot stays under the whole-body
controller while it holds a box, stands on a platform, holds a reach or stands at a height the
walking policy cannot hold (below `policy_height_m[0]`); otherwise it stands up and hands back.

The skills live in their own modules over a shared GoalContext (context.py): approach.py (walking
to a work stance, the hand-over to the whole-body controller, stepping into the stance), reach.py,
handling.py (pick, carry, place a box) and platform.py (step up, step down). This module keeps the
tick, the dispatch of goals to skills, the idle heights and the hand-back to the walking policy.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Callable, Iterator

import numpy as np

from g1_control.generator.goals.approach import enter_whole_body, stand_holding
from g1_control.generator.goals.bottle import pick_bottle, place_bottle, turned_moments
from g1_control.generator.goals.box import GRASP_DISTANCE_M
from g1_control.generator.goals.context import ARMS, GoalConfig, GoalContext, GoalFailed, world_pose_needed
from g1_control.generator.goals.handling import held_forces, pick, place
from g1_control.generator.goals.platform import step_down, step_up
from g1_control.generator.goals.poses import PosePlanner, ReachRefused, flat_soles
from g1_control.generator.goals.reach import reach
from g1_control.generator.styles import ROLLOUT_STYLES
from g1_control.generator.whole_body import keyframe_trajectory
from g1_control.interfaces import Generator, WorldPoseEstimate
from g1_control.robot import g1
from g1_control.rotations import yaw_of
from g1_control.scene import SceneConfig
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


def pick_object(ctx: GoalContext, goal: TaskGoal) -> Iterator[None]:
    """A pick: of a bottle with one hand (bottle.py) when `object` names one, else of a box with both."""
    if goal.object is not None and ctx.scene.bottle(goal.object) is not None:
        return pick_bottle(ctx, goal)
    return pick(ctx, goal)


def place_object(ctx: GoalContext, goal: TaskGoal) -> Iterator[None]:
    """A place: of the bottle in a hand (bottle.py), else of the box held."""
    if ctx.held_bottle is not None:
        return place_bottle(ctx, goal)
    if goal.object is not None and ctx.scene.bottle(goal.object) is not None:
        raise GoalFailed(f"not holding bottle '{goal.object}'")
    return place(ctx, goal)


SKILLS: dict[str, Callable[[GoalContext, TaskGoal], Iterator[None]]] = {
    "reach": reach, "pick": pick_object, "place": place_object, "step_up": step_up, "step_down": step_down}
"""Goal kind -> its skill."""
HAND_BACK_AFTER = frozenset({"place", "step_down"})
"""Goals after which the robot hands back to the walking policy (unless it stands on a platform)."""


class GoalGenerator(Generator):
    """See the module docstring. inner: the launch file's generator, for everything but goals."""

    def __init__(self, inner: Generator, scene: SceneConfig, config: GoalConfig | None = None):
        self.inner = inner
        self.config = config or GoalConfig()
        self.ctx = GoalContext(scene, self.config)
        """What the skills share (context.py)."""
        self.scene = self.ctx.scene
        """The goals' scene: the launch file's, with the platforms where perception sees them."""
        self.poses = self.ctx.poses
        self.ik = self.poses.ik
        self.goal_status: dict[str, str] = {}
        self.goal_messages: dict[str, str] = {}
        self.plan_cpu_s = self.ctx.plan_cpu_s
        self.goal_info = self.ctx.goal_info
        """Per goal, for judging it from outside: kind, start/end time, the hold window of a reach,
        its target in the world (reach point, box, where the box goes, platform)."""
        self.log = self.goal_log = self.ctx.log
        self.plan_windows = self.ctx.plan_windows
        self.estimate: WorldPoseEstimate | None = None
        """Where the robot is for the goals (steer_by); None: the state's own base pose (ground truth)."""
        self._ref = KinematicReference()
        self._joint = JointReference()
        from g1_control.generator.velocity import VelocityReferenceGenerator

        self.walker: Generator = inner if isinstance(inner, VelocityReferenceGenerator) else VelocityReferenceGenerator()
        """Takes a goal's approach walk (module docstring); the inner generator itself when that is one.
        Its references carry their own feasible plan, which the IK stage passes on (ik/stage.py)."""
        self.walking_to_goal = False
        """This tick's locomotion reference is the walker's."""
        self.reset_state()

    # -- lifecycle ------------------------------------------------------------------------------
    def reset_state(self) -> None:
        self.ctx.reset()
        self._queue: deque[TaskGoal] = deque()
        self.ctx.queued = self._queue
        self._seen: set[str] = set()
        self._coro: Iterator[None] | None = None
        self._height: float | None = None
        self._style = "default"
        self._command = Command()
        self.walking_to_goal = False
        self._walking_held = False
        """This tick's reference walks holding something (GoalContext.carry_q)."""

    def reset(self, state: RobotState) -> None:
        self.reset_state()
        self.inner.reset(state)
        self.walker.reset(state)

    def close(self) -> None:
        self.ctx.close()
        self.inner.close()

    def steer_by(self, estimate: WorldPoseEstimate) -> None:
        """Goals are placed by the robot's own estimate (the state the skills see carries it as its
        base pose); the launch file's generator in between still sees the robot's state as reported."""
        self.estimate = estimate

    @property
    def phase(self) -> str:
        return self.ctx.phase

    @phase.setter
    def phase(self, value: str) -> None:
        self.ctx.phase = value

    @property
    def on_platform(self) -> str | None:
        return self.ctx.on_platform

    @property
    def box_positions(self) -> dict[str, np.ndarray | None]:
        return self.ctx.box_positions

    @property
    def last_steps(self):
        return self.ctx.last_steps

    @property
    def busy(self) -> bool:
        return self._coro is not None or bool(self._queue)

    @property
    def holding(self) -> str | None:
        return self.ctx.held.box.name if self.ctx.held else None

    # -- the tick ---------------------------------------------------------------------------------
    def update(self, command: Command, state: RobotState) -> KinematicReference:
        ctx = self.ctx
        self._pause_plan_for_a_stall(state.t_s)
        ctx.state, self._command, ctx.t = self._located(state), command, state.t_s
        for goal in command.tasks:
            if goal.goal_id not in self._seen:
                self._seen.add(goal.goal_id)
                self._queue.append(goal)
        if self._coro is None:
            if self._queue:
                ctx.goal = self._queue.popleft()
                self._coro = self._run_goal(ctx.goal)
            else:
                self._coro = self._idle(command)
        if self._coro is not None:
            try:
                next(self._coro)
            except StopIteration:
                self._coro = None
        return self._reference(command, state)

    def _pause_plan_for_a_stall(self, t_s: float) -> None:
        """GoalConfig.plan_pause_after_s: the part of a stall past it moves the running plan's start (and
        an arm overlay's) on by as much, so the plan resumes where the robot was held."""
        ctx, after = self.ctx, self.config.plan_pause_after_s
        gap = t_s - ctx.t
        if after <= 0 or ctx.state is None or gap <= after or ctx.phase != PHASE_WHOLE_BODY or ctx.plan is None:
            return
        excess = gap - after
        ctx.plan_t0 += excess
        if ctx.overlay is not None:
            ctx.overlay = (ctx.overlay[0], ctx.overlay[1] + excess)
        ctx.stalls += 1
        ctx.stalled_s += excess
        ctx.note(f"the loop stalled {gap * 1000:.0f} ms: the plan paused {excess * 1000:.0f} ms of it")

    def _located(self, state: RobotState) -> RobotState:
        if self.estimate is None:
            return state
        self._perceive(self.estimate.object_positions(), self.estimate.platforms_seen())
        return self.estimate.scene_state(state)

    def _perceive(self, seen, platforms=None) -> None:
        """Boxes where perception last saw them (scene frame), except the one in the hands; platforms
        where it sees them (GoalContext.see_platform)."""
        ctx = self.ctx
        held = ctx.held.box.name if ctx.held is not None else None
        for name, position in seen.items():
            if name in ctx.box_positions and name != held:
                ctx.box_positions[name] = position
        for platform in (platforms or {}).values():
            ctx.see_platform(platform)

    def _reference(self, command: Command, state: RobotState) -> KinematicReference:
        ref = self._plan_reference(command, state)
        ref.grasp_nm[:] = self.ctx.grasp_nm  # the fingers' grasps (trackers/hands.py), whoever planned the body
        return ref

    def _plan_reference(self, command: Command, state: RobotState) -> KinematicReference:
        ctx = self.ctx
        if ctx.carry_q is not None and ctx.phase != PHASE_WHOLE_BODY:
            if not self._walking_held:  # the walk starts from where the robot is
                self.walker.reset(state)
                self._walking_held = True
            if self._coro is not None and ctx.goal is not None:  # a goal's walk (approach.walk_holding)
                command = Command(vx_mps=float(ctx.walk[0]), vy_mps=float(ctx.walk[1]),
                                  wz_radps=float(ctx.walk[2]), style=command.style)
            return self._holding_reference(command, state)
        self._walking_held = False
        if ctx.phase == PHASE_WHOLE_BODY:
            assert ctx.plan is not None
            j = ctx.plan.sample(ctx.t - ctx.plan_t0, self._joint)
            self._bottle_wrench(j, yaw_of(j.root_quat_wxyz))
            if ctx.overlay is not None:
                style, t0 = ctx.overlay
                q_now, q_next = style.pose(ctx.t - t0), style.pose(ctx.t - t0 + 0.01)
                j.q_rad[ARMS] = q_now[ARMS]
                j.dq_radps[ARMS] = (q_next[ARMS] - q_now[ARMS]) / 0.01
            ref = self._ref.set_from(j)
            ref.upper_body_override = True
            ref.pelvis_height_m = None
            ref.style = command.style
            return ref
        own_walker = self.walker is not self.inner
        if self._coro is not None and ctx.goal is not None:
            walk = Command(vx_mps=float(ctx.walk[0]), vy_mps=float(ctx.walk[1]), wz_radps=float(ctx.walk[2]))
            if own_walker and not self.walking_to_goal:
                self.walker.reset(state)
            self.walking_to_goal = True
            ref = self.walker.update(walk, state)
        else:
            if own_walker and self.walking_to_goal:
                self.inner.reset(state)  # it plans on from where the robot is
            self.walking_to_goal = False
            ref = self.inner.update(command, state)
        ref.phase = PHASE_LOCOMOTION
        return ref

    def _bottle_wrench(self, j: JointReference, yaw: float) -> None:
        """A held bottle's weight, off the hand point, on the holding hand (its moment turned to `yaw`);
        without one, no moments."""
        held = self.ctx.held_bottle
        if held is not None:
            j.hand_forces_w_n[:] = held.forces_w_n
            turned_moments(held, yaw, j.hand_moments_w_nm)
        else:
            j.hand_moments_w_nm[:] = 0.0

    def _holding_reference(self, command: Command, state: RobotState) -> KinematicReference:
        """Walking with a box or a bottle held: the velocity (the walker's limits) for the tracker's own
        gait, the held upper-body posture (GoalContext.carry_q), what is held on the hands turned with the
        robot's heading."""
        carry_q = self.ctx.carry_q
        assert carry_q is not None
        walk = self.walker.update(Command(vx_mps=command.vx_mps, vy_mps=command.vy_mps,
                                          wz_radps=command.wz_radps), state)
        j = self._joint
        j.t_s = state.t_s
        j.q_rad[:] = carry_q
        j.dq_radps[:] = 0.0
        j.root_pos_w_m[:] = walk.root_pos_w_m
        j.root_quat_wxyz[:] = walk.root_quat_wxyz
        j.root_linvel_h_mps[:] = walk.root_linvel_h_mps
        j.root_angvel_h_radps[:] = walk.root_angvel_h_radps
        j.contacts[:] = True
        j.phase = PHASE_LOCOMOTION
        j.upper_body_override = True
        j.pelvis_height_m = command.pelvis_height_m
        yaw = yaw_of(state.imu_quat_wxyz)
        j.hand_forces_w_n[:] = held_forces(self.ctx, yaw)
        self._bottle_wrench(j, yaw)
        ref = self._ref.set_from(j)
        ref.upper_body_override = True
        ref.pelvis_height_m = command.pelvis_height_m
        ref.style = command.style
        return ref

    def joint_reference(self, t_s: float) -> JointReference:
        """The whole-body reference of this tick (with joint velocities and hand forces)."""
        return self._joint

    # -- goals --------------------------------------------------------------------------------------
    def _run_goal(self, goal: TaskGoal) -> Iterator[None]:
        ctx = self.ctx
        gid = goal.goal_id
        ctx.note(f"goal {gid}: {goal.describe()}")
        ctx.info = ctx.goal_info.setdefault(gid, {"kind": goal.kind, "describe": goal.describe(), "start_s": ctx.t})
        try:
            ctx.require_world_pose(goal)  # goals placed in the world need one: GoalFailed without
            run = SKILLS[goal.kind]
            yield from run(ctx, goal)
            if goal.kind in HAND_BACK_AFTER and ctx.on_platform is None:
                yield from self._hand_back()
            self.goal_status[gid] = REACHED
            ctx.note(f"goal {gid}: reached")
        except (GoalFailed, ReachRefused) as exc:
            self.goal_status[gid] = FAILED
            self.goal_messages[gid] = str(exc)
            ctx.note(f"goal {gid}: failed: {exc}")
            if ctx.phase == PHASE_WHOLE_BODY and ctx.plan is None:
                ctx.phase = PHASE_LOCOMOTION
        ctx.walk[:] = 0.0
        ctx.goal = None
        ctx.info["end_s"] = ctx.t
        ctx.info["status"] = self.goal_status.get(gid)

    # -- idle: heights the policy cannot hold, handing back -----------------------------------------
    @staticmethod
    def _moving(command: Command) -> bool:
        return abs(command.vx_mps) > 0.02 or abs(command.vy_mps) > 0.02 or abs(command.wz_radps) > 0.02

    def _idle(self, command: Command) -> Iterator[None] | None:
        cfg = self.config
        ctx = self.ctx
        height = command.pelvis_height_m
        moving = self._moving(command)
        if moving and ctx.held is not None and cfg.walk_while_holding and ctx.phase == PHASE_WHOLE_BODY \
                and ctx.plan is not None and ctx.t - ctx.plan_t0 >= ctx.plan.duration_s:
            return self._walk_holding()
        low = height is not None and height < cfg.policy_height_m[0] - 1e-3 and not moving
        if low:
            assert height is not None
            h = max(height, cfg.height_min_m)
            if ctx.phase != PHASE_WHOLE_BODY or self._height is None or abs(h - self._height) > 2e-3 \
                    or command.style != self._style:
                return self._stand_at(h, command.style)
            return None
        if ctx.phase == PHASE_WHOLE_BODY and ctx.held is None and ctx.on_platform is None \
                and ctx.plan is not None and ctx.t - ctx.plan_t0 >= ctx.plan.duration_s \
                and (moving or not ctx.keep or self._height is not None):
            return self._hand_back()
        return None

    def _walk_holding(self) -> Iterator[None]:
        """Walk with the box held while the operator commands motion (GoalConfig.walk_while_holding);
        once the command is zero and the robot has settled, hold it under a whole-body plan again
        from the measured pose, where a place (or the next walk) starts."""
        ctx, cfg = self.ctx, self.config
        assert ctx.held is not None
        ctx.carry_q = ctx.hold_q()[7:].copy()
        ctx.note(f"walk holding '{ctx.held.box.name}'")
        ctx.phase = PHASE_LOCOMOTION
        ctx.plan = None
        still_since: float | None = None
        while True:
            yield
            s = ctx.state
            assert s is not None
            speed = float(np.hypot(*s.base_linvel_w_mps[:2])) if s.base_linvel_w_mps is not None else 0.0
            if self._moving(self._command) or speed > cfg.settle_speed_mps:
                still_since = None
            elif still_since is None:
                still_since = ctx.t
            elif ctx.t - still_since >= cfg.settle_s:
                break
        box = ctx.held.box
        shift = np.array([-box.mass_kg / self.poses.mass_kg * GRASP_DISTANCE_M, 0.0])
        yield from stand_holding(ctx, shift, lambda heading: held_forces(ctx, heading))

    def _stand_at(self, height: float, style_name: str) -> Iterator[None]:
        ctx = self.ctx
        style = ROLLOUT_STYLES.get(style_name) or ROLLOUT_STYLES["default"]
        if ctx.phase != PHASE_WHOLE_BODY:
            yield from enter_whole_body(ctx)
        q0 = ctx.hold_q()
        soles = flat_soles(self.ik, q0)
        ground = min(s[0][2] for s in soles)
        mean_pose = np.mean([style.pose(t) for t in np.linspace(0.0, 5.0, 26)], axis=0) if style.wave_hz else style.pose(0.0)
        q_goal = yield from ctx.compute(f"height {height:.2f}", PosePlanner.stand, q0, soles, ground + height, mean_pose)
        duration = self.config.move_s * max(1.0, abs(q_goal[2] - q0[2]) / 0.15)
        self._height, self._style = height, style_name
        yield from ctx.run(keyframe_trajectory("height", [(0.0, q0), (duration, q_goal)]), keep=True)
        if style.wave_hz:
            ctx.overlay = (style, ctx.t - duration)

    def _hand_back(self) -> Iterator[None]:
        """Stand up with the default arms and hand over to the walking policy."""
        ctx = self.ctx
        q0 = ctx.hold_q()
        soles = flat_soles(self.ik, q0)
        ground = min(s[0][2] for s in soles)
        q_goal = yield from ctx.compute("stand up", PosePlanner.stand, q0, soles, ground + self.poses.nominal_pelvis_m,
                                        g1.DEFAULT_Q_RAD)
        duration = self.config.move_s * max(0.6, abs(q_goal[2] - q0[2]) / 0.15)
        yield from ctx.run(keyframe_trajectory("stand", [(0.0, q0), (duration, q_goal)]))
        ctx.note("hand back to the walking policy")
        ctx.phase = PHASE_LOCOMOTION
        ctx.plan = None
        self._height = None
        ctx.overlay = None
        assert ctx.state is not None
        self.inner.reset(ctx.state)


__all__ = ["FAILED", "REACHED", "GoalConfig", "GoalFailed", "GoalGenerator", "world_pose_needed"]
