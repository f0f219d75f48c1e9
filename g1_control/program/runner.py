"""Step through a behaviour program inside the control loop: progress in, Command out, outcomes recorded.

Each tick the loop fills a ProgramProgress (base x/y/yaw from ground truth or the estimator, and
the status of the goals the execution layer is working on) and calls `update(now_s, progress)`.
The runner turns the current step into a Command (velocity in the heading frame, heading, style,
pelvis height) and, for reach/pick/place/step steps, a GoalRequest for the execution layer
(`active_goals`; `Command.tasks` carries it as a types.TaskGoal for the goal generator of
tracker.type layer, GoalRequest.to_task_goal; `Command.goals` what the kinematic generator can
express, GoalRequest.to_effector_goals). When a step's condition is met it records a StepOutcome with the
measured value (distance covered, heading error, distance to the place, ...) and moves on.

Walk distances are measured from odometry as the displacement along the direction the walk
started in; turns accumulate the yaw change tick by tick (wrapped to (-pi, pi] per tick), so
360-degree turns work. A step that times out or fails stops the program unless
RunnerConfig.continue_after_failure.
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass, field

import numpy as np

from g1_control.program.program import Program
from g1_control.program.steps import (
    TIMED_STEPS,
    Height,
    Parallel,
    Pick,
    Place,
    Reach,
    Repeat,
    Stand,
    Step,
    StepDown,
    StepUp,
    Style,
    Turn,
    Walk,
)
from g1_control.program.world import START, World
from g1_control.robot import g1
from g1_control.types import Command, EffectorGoal, TaskGoal

COMPLETED, TIMED_OUT, FAILED = "completed", "timed_out", "failed"
REACHED, GOAL_FAILED = "reached", "failed"


def wrap_angle(a: float) -> float:
    """a wrapped to [-pi, pi)."""
    return (a + math.pi) % (2 * math.pi) - math.pi


@dataclass
class GoalRequest:
    """A goal for the execution layer: reach a point with a hand, pick/place an object, step up/down.

    target_w_m is resolved from the World when the step starts (object centre, surface, platform,
    or place + offset); offset_b_m is a hand offset (x forward, y left, z up) from the hand's
    standing position when no place is named. `goal_id` is what ProgramProgress.goal_status reports on.
    """

    goal_id: str
    kind: str
    """'reach', 'pick', 'place', 'step_up' or 'step_down'."""
    hand: str | None = None
    object: str | None = None
    target: str | None = None
    target_w_m: np.ndarray | None = None
    offset_b_m: np.ndarray | None = None
    target_kind: str | None = None
    """The World's kind of `target` (object / surface / platform / point); None without one."""

    def to_task_goal(self) -> TaskGoal:
        """The goal for the execution layer (types.TaskGoal, g1_control/generator/goals/): same id,
        so GoalGenerator.goal_status[goal_id] answers ProgramProgress.goal_status. Places are
        passed by name (a table or platform of the launch file's scene is found by it: a place goes
        where the execution layer can reach, the middle of the table's near edge) and by point (a
        named point, the start)."""
        hand = self.hand if self.hand in ("left", "right", "both") else "right"
        if self.kind == "reach":
            return TaskGoal("reach", self.goal_id, hand, pos_w_m=None if self.target_w_m is None else self.target_w_m.copy(),
                            offset_h_m=None if self.target_w_m is not None or self.offset_b_m is None
                            else self.offset_b_m.copy())
        if self.kind == "pick":
            return TaskGoal("pick", self.goal_id, hand, object=self.object)
        if self.kind == "place":
            on_block = self.target_kind in ("surface", "platform")
            return TaskGoal("place", self.goal_id, hand, object=self.object, target=self.target if on_block else None,
                            pos_w_m=None if self.target_w_m is None or on_block else self.target_w_m.copy())
        return TaskGoal(self.kind, self.goal_id, hand, target=self.target)

    def to_effector_goals(self) -> list[EffectorGoal]:
        """What today's generator can express (generator.runtime OBJECT_GOALS and hand frames);
        place and step_down have no equivalent there yet, and give []."""
        if self.target_w_m is None:
            return []
        if self.kind == "reach":
            hands = {"left": g1.HAND_BODIES[:1], "right": g1.HAND_BODIES[1:], "both": g1.HAND_BODIES}[self.hand or "right"]
            return [EffectorGoal(h, self.target_w_m.copy()) for h in hands]
        if self.kind == "pick":
            return [EffectorGoal("box_pick", self.target_w_m.copy())]
        if self.kind == "step_up":
            return [EffectorGoal("box_climb", self.target_w_m.copy())]
        return []


@dataclass
class ProgramProgress:
    """What the loop knows this tick: the base's planar pose (world frame) and the goals' status."""

    x_m: float = 0.0
    y_m: float = 0.0
    yaw_rad: float = 0.0
    goal_status: dict[str, str] = field(default_factory=dict)
    """GoalRequest.goal_id -> 'reached' or 'failed' (absent: still working on it)."""
    pelvis_height_m: float | None = None


@dataclass
class StepOutcome:
    label: str
    """Position in the program: '3', or '2.1#2' (step 1 of repeat 2, second time)."""
    kind: str
    description: str
    status: str
    """'completed', 'timed_out' or 'failed'."""
    started_s: float
    ended_s: float
    measured: dict[str, float] = field(default_factory=dict)

    def describe(self) -> str:
        vals = ", ".join(f"{k} {v:.3g}" for k, v in self.measured.items())
        return (f"{self.label}. {self.description}: {self.status} after {self.ended_s - self.started_s:.1f} s"
                + (f" ({vals})" if vals else ""))


@dataclass
class RunnerConfig:
    walk_speed_mps: dict[str, float] = field(default_factory=lambda: {
        "forward": 0.5, "backward": 0.3, "left": 0.25, "right": 0.25})
    yaw_rate_radps: float = 0.6
    min_speed_mps: float = 0.08
    """Walks slow down as they near the end (speed = gain x remaining) but not below this."""
    slowdown_gain_per_s: float = 0.8
    distance_tolerance_m: float = 0.02
    place_tolerance_m: float = 0.05
    min_yaw_rate_radps: float = 0.12
    turn_gain_per_s: float = 2.0
    heading_tolerance_rad: float = math.radians(1.5)
    heading_hold_gain_per_s: float = 1.5
    """Walks steer the heading back to their start (or target) heading with this gain."""
    timeout_factor: float = 2.0
    timeout_margin_s: float = 5.0
    """A step without timeout_s gets factor x the nominal time + margin (walk/turn), or goal_timeout_s."""
    goal_timeout_s: dict[str, float] = field(default_factory=lambda: {
        "reach": 30.0, "pick": 60.0, "place": 90.0, "step_up": 45.0, "step_down": 45.0})
    """Upper bounds on the execution layer's goals, walking to the work included (MuJoCo, tracker.type
    layer: pick ~16 s, a 3 m carry and place ~45-50 s, step up ~20 s; notes 15_part2.md)."""
    posture_height_m: dict[str, float | None] = field(default_factory=lambda: {
        "crouch": 0.62, "normal": None, "tall": 0.8})
    """None: the generator's own height for the style."""
    height_settle_s: float = 1.5
    """A height step without a duration completes after this (the body gets there)."""
    walk_settle_max_s: float = 2.0
    """A walk that reached its end commands zero velocity until the robot is at rest (moved less than
    still_speed_mps x still_window_s over the last still_window_s), at most this long; its outcome is
    measured there, so the next step starts from rest and a walk's figures include its run-out
    (0: complete at once, still moving)."""
    still_speed_mps: float = 0.05
    still_window_s: float = 0.3
    runout_m: float = 0.03
    """A walk by a distance stops commanding this much early: the walking policy runs on by about
    that much once its velocity goes to zero (MuJoCo, holosoma ppo: 0-9 cm, mean ~3 cm over 24 walks)."""
    walk_corrections: int = 2
    """A walk by a distance that came to rest more than correction_tolerance_m off (by odometry, which
    reads without sway at rest) walks the rest (or back) at correction_speed_mps, up to this often."""
    correction_tolerance_m: float = 0.03
    correction_speed_mps: float = 0.12
    gait_period_s: float = 1.0
    """The walking policy's gait period (holosoma: 1 s): walks judge their progress on the position
    averaged over one period (the pelvis sways +-3-5 cm sideways with each step), brought up to
    now by half the period's displacement. 0: the raw position."""
    continue_after_failure: bool = False


PLACE_WALK_BUDGET_S = 60.0
"""time_budget_s: a walk to a place, whose length is known only when it starts."""


def time_budget_s(program: Program, config: RunnerConfig | None = None) -> float:
    """An upper bound on how long `program` runs: every step's timeout (or its time), repeats
    expanded, as the runner would give them (a walk to a place: PLACE_WALK_BUDGET_S unless it has
    a timeout). Launch files size a program run by it; the run ends early when the program does."""
    cfg = config or RunnerConfig()
    leaves: list[_Leaf] = []
    _flatten(program.steps, "", leaves)

    def budget(step: Step) -> float:
        if isinstance(step, Parallel):
            return budget(step.main)
        timeout = step.timeout_s if isinstance(step, TIMED_STEPS) else None
        if timeout is not None:
            return timeout
        if isinstance(step, Walk):
            if step.distance_m is None:
                return step.duration_s if step.duration_s is not None else PLACE_WALK_BUDGET_S
            speed = step.speed_mps or cfg.walk_speed_mps[step.direction]
            return cfg.timeout_factor * step.distance_m / speed + cfg.timeout_margin_s
        if isinstance(step, Turn):
            rate = step.yaw_rate_radps or cfg.yaw_rate_radps
            angle = step.angle_rad if step.angle_rad is not None else math.pi
            return cfg.timeout_factor * angle / rate + cfg.timeout_margin_s
        if isinstance(step, (Stand, Style, Height)):
            hold = step.duration_s
            return hold if hold is not None else cfg.height_settle_s
        return cfg.goal_timeout_s[step.kind]

    return sum(budget(leaf.step) for leaf in leaves)


@dataclass
class _Leaf:
    label: str
    step: Step


def _flatten(steps: list[Step], prefix: str, out: list[_Leaf]) -> None:
    for i, s in enumerate(steps):
        label = f"{prefix}{i + 1}"
        if isinstance(s, Repeat):
            for k in range(s.count):
                sub: list[_Leaf] = []
                _flatten(s.steps, label + ".", sub)
                out.extend(_Leaf(f"{leaf.label}#{k + 1}", leaf.step) for leaf in sub)
        else:
            out.append(_Leaf(label, s))


class _Active:
    """Book-keeping of the step being run."""

    def __init__(self, leaf: _Leaf, now_s: float, p: ProgramProgress) -> None:
        self.leaf = leaf
        self.t0 = now_s
        self.x0, self.y0, self.yaw0 = p.x_m, p.y_m, p.yaw_rad
        self.last_yaw = p.yaw_rad
        self.turned = 0.0
        self.timeout_s = math.inf
        self.goals: list[GoalRequest] = []
        self.target_xy: np.ndarray | None = None
        self.stop_m = 0.0
        self.walk_dir_w = np.array([1.0, 0.0])
        self.hold_heading = p.yaw_rad
        self.reached_xy: tuple[float, float] | None = None
        self.corrections = 0
        self.settle_t0: float | None = None
        """When a walk reached its end and started coming to rest (elapsed s); None while walking."""
        self.track: deque[tuple[float, float, float]] = deque()
        """(elapsed, x, y) over the last RunnerConfig.still_window_s, for telling rest."""


class ProgramRunner:
    """Runs a validated Program against a World; one `update` per control tick."""

    def __init__(self, program: Program, world: World | None = None, config: RunnerConfig | None = None) -> None:
        self.world = world if world is not None else World()
        self.program = program.validate(self.world)
        self.config = config or RunnerConfig()
        self._leaves: list[_Leaf] = []
        _flatten(program.steps, "", self._leaves)
        self._next = 0
        self._active: _Active | None = None
        self._start_xy: np.ndarray | None = None
        self._goal_counter = 0
        self.style = "default"
        self.pelvis_height_m: float | None = None
        self.outcomes: list[StepOutcome] = []
        self.stopped = False
        """True when a step timed out or failed and the program was stopped there."""

    # --- public state ----------------------------------------------------------------------
    @property
    def done(self) -> bool:
        return self.stopped or (self._active is None and self._next >= len(self._leaves))

    @property
    def current_label(self) -> str | None:
        return self._active.leaf.label if self._active else None

    @property
    def active_goals(self) -> list[GoalRequest]:
        return list(self._active.goals) if self._active else []

    def update(self, now_s: float, progress: ProgramProgress) -> Command:
        """The command for this tick; starts, finishes and records steps as their conditions are met."""
        if self._start_xy is None:
            self._start_xy = np.array([progress.x_m, progress.y_m])
        for _ in range(len(self._leaves) + 1):  # steps that finish at once hand on in the same tick
            if self.done:
                return self._idle()
            if self._active is None:
                self._active = self._begin(self._leaves[self._next], now_s, progress)
                self._next += 1
            a = self._active
            a.turned += wrap_angle(progress.yaw_rad - a.last_yaw)
            a.last_yaw = progress.yaw_rad
            cmd, finished = self._tick(a, a.leaf.step, now_s, progress)
            if finished is None and now_s - a.t0 > a.timeout_s:
                finished = (TIMED_OUT, self._measure(a, a.leaf.step, progress))
            if finished is None:
                return cmd.validate()
            self._finish(a, finished[0], finished[1], now_s)
        return self._idle()

    def summary(self) -> str:
        return "\n".join(o.describe() for o in self.outcomes)

    def step_of(self, label: str) -> Step:
        """The step an outcome's label names ('3', '2.1#2')."""
        return next(leaf.step for leaf in self._leaves if leaf.label == label)

    @property
    def active_is_locomotion(self) -> bool:
        """The step running now is a walk, turn or stand (alone or as a parallel's main) with no goal."""
        a = self._active
        if a is None or a.goals:
            return False
        main = a.leaf.step.main if isinstance(a.leaf.step, Parallel) else a.leaf.step
        return isinstance(main, (Walk, Turn, Stand))

    def restart_active(self, now_s: float, progress: ProgramProgress) -> None:
        """Start the running locomotion step over from here (its distance, heading and time count
        from now): the program input does this once the execution layer has handed the robot back
        to the walking policy after a goal (the hand-over moves the robot; that is not the walk)."""
        if self.active_is_locomotion:
            assert self._active is not None
            self._active = self._begin(self._active.leaf, now_s, progress)

    def hold_command(self) -> Command:
        """Stand still with the style and height the program has set so far (before it starts, after it ends)."""
        return self._idle()

    # --- step life cycle ---------------------------------------------------------------------
    def _finish(self, a: _Active, status: str, measured: dict[str, float], now_s: float) -> None:
        step = a.leaf.step
        self.outcomes.append(StepOutcome(a.leaf.label, step.kind, step.describe(), status, a.t0, now_s, measured))
        self._active = None
        if isinstance(step, (Style, Height)) and step.duration_s is None:
            self._apply_setting(step)
        if status != COMPLETED and not self.config.continue_after_failure:
            self.stopped = True

    def _apply_setting(self, step: Step) -> None:
        if isinstance(step, Style):
            self.style = step.name
        elif isinstance(step, Height):
            self.pelvis_height_m = self._height(step)

    def _height(self, step: Height) -> float | None:
        if step.pelvis_height_m is not None:
            return step.pelvis_height_m
        assert step.posture is not None  # a valid Height has exactly one of the two
        return self.config.posture_height_m[step.posture]

    def _begin(self, leaf: _Leaf, now_s: float, p: ProgramProgress) -> _Active:
        a = _Active(leaf, now_s, p)
        main = leaf.step.main if isinstance(leaf.step, Parallel) else leaf.step
        cfg = self.config
        where = f"step {leaf.label} ({leaf.step.kind})"
        if isinstance(main, Walk):
            speed = main.speed_mps or cfg.walk_speed_mps[main.direction]
            if main.target is not None:
                a.target_xy, a.stop_m = self._place_xy(main.target, where)
                dist = max(0.0, float(np.linalg.norm(a.target_xy - [p.x_m, p.y_m])) - a.stop_m)
                nominal = dist / speed
            else:
                base = main.heading_rad if main.heading_rad is not None else p.yaw_rad
                rel = {"forward": 0.0, "left": math.pi / 2, "backward": math.pi, "right": -math.pi / 2}[main.direction]
                ang = base + rel
                a.walk_dir_w = np.array([math.cos(ang), math.sin(ang)])
                a.hold_heading = base
                nominal = main.distance_m / speed if main.distance_m is not None else math.inf
            a.timeout_s = main.timeout_s or (cfg.timeout_factor * nominal + cfg.timeout_margin_s
                                             if math.isfinite(nominal) else math.inf)
        elif isinstance(main, Turn):
            rate = main.yaw_rate_radps or cfg.yaw_rate_radps
            need = abs(self._turn_remaining(a, main, p))
            a.timeout_s = main.timeout_s or cfg.timeout_factor * need / rate + cfg.timeout_margin_s
        if isinstance(leaf.step, Parallel):
            for s in leaf.step.alongside:
                if isinstance(s, Reach):
                    a.goals.append(self._goal(s, p, where))
        elif isinstance(leaf.step, (Reach, Pick, Place, StepUp, StepDown)):
            a.goals.append(self._goal(leaf.step, p, where))
            a.timeout_s = leaf.step.timeout_s or cfg.goal_timeout_s[leaf.step.kind]
        return a

    def _place_xy(self, name: str, where: str) -> tuple[np.ndarray, float]:
        if name == START:
            assert self._start_xy is not None  # set on the first tick, before any step begins
            return self._start_xy.copy(), 0.0
        lm = self.world.get(name, where)
        return lm.pos_w_m[:2].copy(), lm.stop_distance_m()

    def _goal(self, step: Step, p: ProgramProgress, where: str) -> GoalRequest:
        self._goal_counter += 1
        gid = f"g{self._goal_counter}"
        name = step.target if isinstance(step, (Reach, Place)) else step.object if isinstance(step, Pick) else \
            step.platform if isinstance(step, (StepUp, StepDown)) else None
        target_w = None
        if name is not None:
            if name == START:
                assert self._start_xy is not None  # set on the first tick, before any step begins
                target_w = np.array([*self._start_xy, 0.0])
            else:
                target_w = self.world.get(name, where).pos_w_m.copy()
        offset_b = None
        if isinstance(step, Reach) and step.offset_m is not None:
            off = np.asarray(step.offset_m, dtype=float)
            if target_w is not None:  # offset from the place, turned into the world by the robot's heading
                c, s = math.cos(p.yaw_rad), math.sin(p.yaw_rad)
                target_w = target_w + np.array([c * off[0] - s * off[1], s * off[0] + c * off[1], off[2]])
            else:
                offset_b = off
        kind = None if name is None else "point" if name == START else self.world.get(name, where).kind
        return GoalRequest(
            gid, step.kind,
            hand=step.hand if isinstance(step, Reach) else step.hands if isinstance(step, Pick) else None,
            object=step.object if isinstance(step, (Pick, Place)) else None,
            target=name if not isinstance(step, Pick) else None,
            target_w_m=target_w, offset_b_m=offset_b, target_kind=kind)

    # --- per-tick behaviour ------------------------------------------------------------------
    def _turn_remaining(self, a: _Active, t: Turn, p: ProgramProgress) -> float:
        if t.angle_rad is not None:
            sign = 1.0 if t.direction == "left" else -1.0
            return sign * t.angle_rad - a.turned
        if t.heading_rad is not None:
            return wrap_angle(t.heading_rad - p.yaw_rad)
        assert t.target is not None  # a valid Turn has an angle, a heading or a target
        tx, ty = self._place_xy(t.target, f"step {a.leaf.label} (turn)")[0]
        return wrap_angle(math.atan2(ty - p.y_m, tx - p.x_m) - p.yaw_rad)

    def _tick(self, a: _Active, step: Step, now_s: float, p: ProgramProgress):
        cmd = Command(style=self.style, pelvis_height_m=self.pelvis_height_m)
        elapsed = now_s - a.t0
        if isinstance(step, Parallel):
            for s in step.alongside:
                if isinstance(s, Style):
                    cmd.style = s.name
                elif isinstance(s, Height):
                    cmd.pelvis_height_m = self._height(s)
            for g in a.goals:
                cmd.goals.extend(g.to_effector_goals())
                cmd.tasks.append(g.to_task_goal())
            return self._tick_main(a, step.main, cmd, elapsed, p)
        if isinstance(step, (Walk, Turn, Stand)):
            return self._tick_main(a, step, cmd, elapsed, p)
        if isinstance(step, (Style, Height)):
            if isinstance(step, Style):
                cmd.style = step.name
            else:
                cmd.pelvis_height_m = self._height(step)
            hold = step.duration_s if step.duration_s is not None else (
                0.0 if isinstance(step, Style) else self.config.height_settle_s)
            if elapsed >= hold:
                measured = {"duration_s": elapsed}
                if isinstance(step, Height) and p.pelvis_height_m is not None:
                    measured["pelvis_height_m"] = p.pelvis_height_m
                return cmd, (COMPLETED, measured)
            return cmd, None
        # goal steps: the execution layer moves; the runner waits for its verdict
        g = a.goals[0]
        cmd.goals.extend(g.to_effector_goals())
        cmd.tasks.append(g.to_task_goal())
        status = p.goal_status.get(g.goal_id)
        if status == REACHED:
            return cmd, (COMPLETED, {"duration_s": elapsed})
        if status == GOAL_FAILED:
            return cmd, (FAILED, {"duration_s": elapsed})
        return cmd, None

    def _tick_main(self, a: _Active, step: Step, cmd: Command, elapsed: float, p: ProgramProgress):
        cfg = self.config
        if isinstance(step, Stand):
            if elapsed >= step.duration_s:
                return cmd, (COMPLETED, self._measure(a, step, p))
            return cmd, None
        if isinstance(step, Turn):
            rem = self._turn_remaining(a, step, p)
            if abs(rem) <= cfg.heading_tolerance_rad:
                return cmd, (COMPLETED, self._measure(a, step, p))
            rate = step.yaw_rate_radps or cfg.yaw_rate_radps
            mag = min(rate, max(cfg.min_yaw_rate_radps, cfg.turn_gain_per_s * abs(rem)))
            cmd.wz_radps = math.copysign(mag, rem)
            return cmd, None
        assert isinstance(step, Walk)
        speed = step.speed_mps or cfg.walk_speed_mps[step.direction]
        pos = np.array([p.x_m, p.y_m])
        a.track.append((elapsed, p.x_m, p.y_m))
        while a.track and a.track[0][0] < elapsed - max(cfg.still_window_s, cfg.gait_period_s):
            a.track.popleft()
        if cfg.gait_period_s > 0 and a.track[-1][0] - a.track[0][0] >= 0.95 * cfg.gait_period_s:
            # sway-free position: the mean over one gait period is where the robot was half a period
            # ago; the displacement over the period (also sway-free) brings it up to now
            track = np.asarray(a.track)
            pos = track[:, 1:].mean(axis=0) + (track[-1, 1:] - track[0, 1:]) / 2
        if a.settle_t0 is None:
            reached = False
            if step.target is not None:
                reached = float(np.hypot(*(a.target_xy - pos))) - a.stop_m <= cfg.place_tolerance_m
            elif step.distance_m is not None:
                remaining = step.distance_m - float((pos - [a.x0, a.y0]) @ a.walk_dir_w)
                reached = abs(remaining) <= cfg.distance_tolerance_m if a.corrections else \
                    remaining <= cfg.distance_tolerance_m + cfg.runout_m
            elif step.duration_s is not None:
                reached = elapsed >= step.duration_s
            if reached:
                a.settle_t0 = elapsed
                a.reached_xy = (p.x_m, p.y_m)
        if a.settle_t0 is not None:  # coming to rest: zero velocity, heading held
            t0, x0, y0 = next(e for e in a.track if e[0] >= elapsed - cfg.still_window_s - 1e-9)
            window = elapsed - a.settle_t0 >= cfg.still_window_s and elapsed - t0 >= 0.8 * cfg.still_window_s
            still = window and math.hypot(p.x_m - x0, p.y_m - y0) <= cfg.still_speed_mps * cfg.still_window_s
            if still and step.distance_m is not None and a.corrections < cfg.walk_corrections:
                # at rest, where odometry reads without sway: close the loop on what is left
                left = step.distance_m - float((np.array([p.x_m, p.y_m]) - [a.x0, a.y0]) @ a.walk_dir_w)
                if abs(left) > cfg.correction_tolerance_m:
                    a.corrections += 1
                    a.settle_t0 = None
                    return self._tick_main(a, step, cmd, elapsed, p)
            if still or elapsed - a.settle_t0 >= cfg.walk_settle_max_s:
                return cmd, (COMPLETED, self._measure(a, step, p))
            if step.target is None:
                err = wrap_angle(a.hold_heading - p.yaw_rad)
                cmd.heading_rad = a.hold_heading
                cmd.wz_radps = float(np.clip(cfg.heading_hold_gain_per_s * err, -cfg.yaw_rate_radps,
                                             cfg.yaw_rate_radps))
            return cmd, None
        if step.target is not None:
            d = a.target_xy - pos
            dist = float(np.hypot(*d))
            remaining = dist - a.stop_m
            bearing = math.atan2(d[1], d[0])
            err = wrap_angle(bearing - p.yaw_rad)
            v = min(speed, max(cfg.min_speed_mps, cfg.slowdown_gain_per_s * remaining))
            cmd.vx_mps = v * max(0.0, math.cos(err)) ** 2  # turn toward it first when it is off to a side
            cmd.heading_rad = bearing
            cmd.wz_radps = float(np.clip(cfg.heading_hold_gain_per_s * err, -cfg.yaw_rate_radps, cfg.yaw_rate_radps))
            return cmd, None
        if step.distance_m is not None:
            remaining = step.distance_m - float((pos - [a.x0, a.y0]) @ a.walk_dir_w)
            v = math.copysign(min(speed, max(cfg.correction_speed_mps if a.corrections else cfg.min_speed_mps,
                                             cfg.slowdown_gain_per_s * abs(remaining))), remaining)
        else:
            v = speed
        # velocity in the heading frame along the walk's world direction, heading held
        c, s = math.cos(p.yaw_rad), math.sin(p.yaw_rad)
        dx, dy = a.walk_dir_w
        cmd.vx_mps, cmd.vy_mps = v * (c * dx + s * dy), v * (-s * dx + c * dy)
        err = wrap_angle(a.hold_heading - p.yaw_rad)
        cmd.heading_rad = a.hold_heading
        cmd.wz_radps = float(np.clip(cfg.heading_hold_gain_per_s * err, -cfg.yaw_rate_radps, cfg.yaw_rate_radps))
        return cmd, None

    def _measure(self, a: _Active, step: Step, p: ProgramProgress) -> dict[str, float]:
        if isinstance(step, Parallel):
            return self._measure(a, step.main, p)
        pos = np.array([p.x_m, p.y_m])
        moved = pos - [a.x0, a.y0]
        if isinstance(step, Walk):
            if step.target is not None:
                return {"distance_to_place_m": float(np.hypot(*(a.target_xy - pos))), "stop_distance_m": a.stop_m}
            along = float(moved @ a.walk_dir_w)
            side = float(moved[0] * -a.walk_dir_w[1] + moved[1] * a.walk_dir_w[0])
            out = {"distance_m": along, "lateral_m": side}
            if a.reached_xy is not None:  # how far it ran on after the velocity went to zero
                out["runout_m"] = float((pos - a.reached_xy) @ a.walk_dir_w)
            if a.corrections:
                out["corrections"] = float(a.corrections)
            if step.distance_m is not None:
                out["error_m"] = along - step.distance_m
            return out
        if isinstance(step, Turn):
            return {"turned_rad": a.turned, "heading_error_rad": self._turn_remaining(a, step, p)}
        if isinstance(step, Stand):
            return {"drift_m": float(np.hypot(*moved))}
        return {}

    def _idle(self) -> Command:
        return Command(style=self.style, pelvis_height_m=self.pelvis_height_m)


__all__ = [
    "COMPLETED",
    "FAILED",
    "TIMED_OUT",
    "GoalRequest",
    "ProgramProgress",
    "ProgramRunner",
    "RunnerConfig",
    "StepOutcome",
    "time_budget_s",
    "wrap_angle",
]
