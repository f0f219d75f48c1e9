"""GoalContext: what the goal skills share with each other and with the executor (executor.py).

The skills (approach.py, reach.py, handling.py, platform.py) are generator functions over one
context: the scene and the planners, the whole-body plan being followed (and when it started),
the walking command of an approach, the box held, the platform stood on, where the boxes are, the
robot's state this tick and the current goal's record. The context's own steps are the ones every
skill uses: where the reference is (`hold_q`), the drift of the plan frame (`offset`), following a
plan (`run`), planning (`compute`), and the robot's world pose (`world_pose`, the one place that
requires it).
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable, Generator, Iterator, Sequence
from dataclasses import dataclass, field
from typing import Any, TypeVar

import numpy as np

from g1_control.generator.goals.planner import PlannerDied, PlannerProcess
from g1_control.generator.goals.poses import PosePlanner
from g1_control.generator.goals.stepping import SteppingConfig
from g1_control.generator.styles import UpperBodyStyle
from g1_control.generator.whole_body import WholeBodyTrajectory
from g1_control.robot import g1
from g1_control.scene import Bottle, Box, Platform, SceneConfig
from g1_control.types import PHASE_LOCOMOTION, PHASE_WHOLE_BODY, RobotState, TaskGoal

ARMS = np.array(g1.ARM_JOINTS)
T = TypeVar("T")


class GoalFailed(RuntimeError):
    """A goal that cannot be done (the message says why)."""


def world_pose_needed(goal: TaskGoal) -> str | None:
    """Why `goal` needs the robot's pose in the world, or None where it runs without one.

    A reach given relative to the robot (offset_h_m) is planned in the frame of the stance the
    robot stands in, and so are heights (Command.pelvis_height_m); everything placed in the scene
    (world points, boxes, tables, platforms) is found only from where the robot is in the world."""
    if goal.kind == "reach":
        if goal.pos_w_m is None:
            return None
        return "a reach to a world point (pos_w_m) needs to know where the robot is; give it relative to the robot (offset_h_m)"
    what = {"pick": "a pick finds its box in the scene", "place": "a place finds where the box goes in the scene",
            "step_up": "a step up finds its platform in the scene",
            "step_down": "a step down finds the floor behind the platform in the scene"}[goal.kind]
    return f"{what}, which needs to know where the robot is"


@dataclass
class GoalConfig:
    walk_speed_mps: float = 0.4
    turn_rate_radps: float = 0.6
    approach_offset_m: float = 0.2
    """The walking policy stops this much short of a work stance; the whole-body controller steps
    the rest (the policy stops within ~5-10 cm; footsteps are exact)."""
    approach_tolerance_m: float = 0.08
    approach_heading_tolerance_rad: float = 0.12
    approach_settled_tolerance_m: float = 0.16
    """Once within approach_tolerance_m the walk stops and the robot stands until settled; only then is the
    distance judged again, against this: a stop coasts on (the whole-body controller's gait, stopping
    from 0.15 m/s sideways, carried the pelvis ~0.1 m on, measured), and judged while coasting the
    approach walked back and forth past its stance for the whole pick segment (launch/sim_wbc_carry.yaml,
    stop 42). The work stance's own steps (step_to) take the rest."""
    approach_settled_heading_tolerance_rad: float = 0.25
    """... and the heading against this. The walking policy stops turning once within
    approach_heading_tolerance_rad and, standing, sways its heading by ~0.01 rad: judged settled against
    that tolerance again, the approach stood at 0.12 +- 0.005 rad off for the whole walk timeout, a tick of
    small turn command between each second of standing (`g1 bench objects --seed 61` trials 3, 6, 9 and
    seed 62 trial 6: 4 of 30 picks failed "did not reach the stance"). The work stance's steps turn the rest."""
    settle_s: float = 1.0
    """Standing still this long (speed below settle_speed_mps) before a hand-over."""
    settle_speed_mps: float = 0.05
    walk_timeout_s: float = 45.0
    carry_walk_speed_mps: float = 0.25
    carry_turn_rate_radps: float = 0.4
    """Walking holding something in a goal (approach.walk_holding, the tracker's own gait): at most this fast."""
    gait_carry_max_kg: float = 5.0
    """A goal carries a box this heavy at most in the tracker's own gait (walk_while_holding); a heavier one
    in whole-body steps. With 5.3 and 5.7 kg boxes the gait staggered (the pelvis bobbing 0.60-0.72 m, the
    robot moving 1.2 m/s at 0.25 commanded) and fell, on the tracking layer at 100 and 250 Hz and on the
    WBC alone (`g1 bench objects` scenes 147.7, 143.0); 4.4 and 4.5 kg boxes were carried and placed
    (141.16, 144.17, which fell in whole-body steps). With the pelvis held while holding
    (WbcConfig.walking_held_pelvis), on the layer at 250 Hz: 147.7 placed in the gait, 143.0 did not reach
    its stance within the walk's 45 s and fell after (in whole-body steps it falls too). Measured, one
    machine, stop 56."""
    stand_s: float = 1.0
    """After a hand-over: from the measured pose to a clean standing pose."""
    move_s: float = 2.0
    """Joint-space moves of the arms and the body (reach, height)."""
    reach_hold_s: float = 1.5
    squeeze_n: float = 20.0
    """Per hand, at least: twice the Coulomb minimum for a 2 kg box at mu 1 (m g / 2 mu = 9.8 N);
    a heavier or more slippery box is squeezed with 1.3 times its own minimum (Held.squeeze_n)."""
    lift_m: float = 0.10
    pre_gap_m: float = 0.065
    press_m: float = 0.01
    """Hand targets this far inside the box's faces (the squeeze is the known force; this keeps contact)."""
    force_ramp_s: float = 0.4
    backup_m: float = 0.3
    """Steps back from a table before turning with a box."""
    carry_over_check: bool = True
    """A box carried to a table: the carry's plan is checked from the planned hand points less the
    measured sag of the hands (joint angles and IMU, handling.hands_sag_m) and, where the box's bottom
    would pass less than BOX_OVER_TOP_M over the top, walked with the pelvis kept at the raise's
    height, the box raised further, or refused (handling.carry). Off: only the standing raise before
    the carry checks (it ended 3 cm short at the arms' reach, the carry's walking pelvis took the
    hands 2 cm lower, the hands sagged 1 cm: the box dragged 0.5-1 cm over a 0.92 m table and the
    robot fell, bench objects seed 19, trial 8)."""
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
    plan_pause_after_s: float = 0.03
    """A whole-body plan stops where it is when the loop stalls: of a gap longer than this between two
    ticks' states (a stalled host), only this much plays; the rest is added to the plan's start. The robot
    link holds the pose after a command's life (safety.command_hold_ticks: 30 ms at 100 Hz), so a plan that
    played on through a 120 ms stall resumed 90 ms ahead of a robot that had stood still: mid step-up, a
    swing foot expected on the platform and the support switched to it (measured: 3 falls in 8 seeded
    runs of sim2sim_step's timeline with four 120 ms stalls each). 0 plays plans on the state's clock.
    A launch file's loop sets it to the robot link's command life: max(safety.command_hold_ticks, 3) tracker
    ticks (launch/builder.py), so a slower tracker's ticks never count as stalls."""
    sight_wait_s: float = 2.0
    """A step goal whose platform the scene does not hold waits this long, standing (nothing moves), for
    perception to see it (a 10 Hz perception with dropouts: a few frames), then refuses, naming it."""
    policy_height_m: tuple[float, float] = (0.63, 0.78)
    """Pelvis heights the walking policy holds (its envelope); others stand under the WBC."""
    height_min_m: float = 0.45
    walk_while_holding: bool = False
    """A velocity command while a box is held walks with it: the tracker walks by its own gait with
    the held upper-body posture and the box's forces on the hands (the whole-body controller with
    footsteps 'velocity', alone or inside the tracking layer, which hands it such a walk). Off (a walking
    policy would drop the box), the robot stands holding it."""
    bottle_grasp_nm: float = 0.5
    """A bottle's one-hand grasp (goals/bottle.py): each finger motor stops squeezing at this torque
    (trackers/grasp.py; the Dex3's motors give 1.4-2.45 N m). 0.5 N m at a finger's ~5 cm lever
    presses ~10 N, five times what holds a 0.4 kg bottle at friction 1 between two sides."""
    bottle_close_s: float = 1.5
    """The hand holds still this long while its fingers close on the bottle (or open off it)."""
    bottle_slide_s: float = 1.0
    """The hand's moves beside the bottle (in to the grasp, the lift, down to the place, back out)."""
    bottle_lift_m: float = 0.10
    plan_in_background: bool = False
    """Plan in the planner's own process (planner.py) while the robot holds its current reference
    (wall-clock runs: a carry's footstep plan takes ~1-2 s of CPU, which would stall the loop). Off
    in lockstep, where planning inline keeps runs deterministic (simulated time waits for it)."""


@dataclass
class Held:
    box: Box
    forces: np.ndarray
    """(2, 3) hand forces while held (world axes at the time of the grasp's heading)."""
    squeeze_n: float = 20.0
    """The squeeze per hand it is held with."""
    heading_rad: float = 0.0
    """The robot's heading when it took the box (the box turns with the robot from there)."""
    hand_dz_m: float = 0.0
    """The hands above the box's centre (stances.hand_height at the pick)."""


@dataclass
class HeldBottle:
    """A bottle in one hand (goals/bottle.py)."""

    bottle: Bottle
    hand: int
    """0 left, 1 right."""
    grasp_above_base_m: float
    """The grasp centre's height above the bottle's base when it was picked."""
    heading_rad: float
    """The palm's heading while it holds the bottle (the plans keep it)."""
    forces_w_n: np.ndarray
    moments_w_nm: np.ndarray
    """(2, 3) each: its weight and that weight's moment about the hand point while held (bottle.held_wrench),
    what the whole-body plan's references carry."""


class GoalContext:
    """The state the goal skills and the executor share (module docstring)."""

    def __init__(self, scene: SceneConfig, config: GoalConfig):
        self.scene = dataclasses.replace(scene, platforms=list(scene.platforms))
        """The launch file's scene, its platforms where perception last saw them (see_platform): a copy,
        so what perception sees stays with the goals and leaves the launch file's scene as written."""
        self._listed_platforms = list(scene.platforms)
        self.config = config
        self.poses = PosePlanner()
        self.ik = self.poses.ik
        self.plan_cpu_s: dict[str, float] = {}
        self.plan_windows: list[tuple[str, float, float]] = []
        """(what, start, end) of every plan, in the state's time (Generator.plan_windows)."""
        self.goal_info: dict[str, dict] = {}
        """Per goal, for judging it from outside: kind, start/end time, the hold window of a reach,
        its target in the world (reach point, box, where the box goes, platform)."""
        self.log: list[tuple[float, str]] = []
        self.info: dict = {}
        """The current goal's entry of goal_info."""
        self.last_steps: Any = None
        """The last footstep plan (stepping.StepPlan), for inspection."""
        self.fingers_driven = False
        """The loop drives the Dex3 fingers (trackers/hands.py; launch/builder.py sets it): without, a grasp the
        plan asks for would close nothing, so a bottle pick refuses."""
        self.planner: PlannerProcess | None = None
        """Where plans are made beside a wall-clock loop (None: inline)."""
        if self.config.plan_in_background:
            self.planner = PlannerProcess()
        self.reset()

    def reset(self) -> None:
        self.phase = PHASE_LOCOMOTION
        self.goal: TaskGoal | None = None
        self.queued: Sequence[TaskGoal] = ()
        """The goals waiting after this one, in order (the executor's queue): a pick grips a box where the
        place queued after it will want it (handling.pick)."""
        self.plan: WholeBodyTrajectory | None = None
        self.plan_t0 = 0.0
        self.walk = np.zeros(3)
        """The walking command (vx, vy, wz) of an approach (approach.walk_to)."""
        self.held: Held | None = None
        self.held_bottle: HeldBottle | None = None
        """The bottle in one hand (goals/bottle.py)."""
        self.carry_q: np.ndarray | None = None
        """Walking with something held (GoalConfig.walk_while_holding): the upper body's held posture (g1 joint
        order; the legs' entries unused) while the tracker walks by its own gait, from the operator's velocity
        between goals or from `walk` in a goal (approach.walk_holding); None otherwise."""
        self.grasp_nm = np.zeros(2)
        """Per hand (left, right): the finger grasp the plan asks for (KinematicReference.grasp_nm)."""
        self.on_platform: str | None = None
        self.scene.platforms[:] = self._listed_platforms
        self.platforms_seen: set[str] = set()
        """Platforms perception has seen since the reset (see_platform)."""
        self.box_positions: dict[str, np.ndarray | None] = {b.name: self.scene.box_center(b) for b in self.scene.boxes}
        self.overlay: tuple[UpperBodyStyle, float] | None = None
        """An upper-body style waving the arms over the plan (style, its start time)."""
        self.keep = False
        """Stay under the whole-body controller after the plan ends (a reach holds its point)."""
        self.step_back = (0.0, 0.0)
        self.t = 0.0
        self.state: RobotState | None = None
        self.stalls = 0
        self.stalled_s = 0.0
        """Stalls that paused a plan (GoalConfig.plan_pause_after_s) and the plan time they held back."""

    def note(self, text: str) -> None:
        self.log.append((self.t, text))

    def see_platform(self, platform: Platform) -> None:
        """Perception sees `platform` (scene frame): it takes the place of the scene's platform of that name
        (the launch file's may be missing or misplaced), or joins the scene. A name the scene gives a table or
        a box stays theirs."""
        platforms = self.scene.platforms
        for i, p in enumerate(platforms):
            if p.name == platform.name:
                platforms[i] = platform
                break
        else:
            if platform.name in self.scene.names():
                return
            platforms.append(platform)
        self.platforms_seen.add(platform.name)

    # -- where the robot is -------------------------------------------------------------------------
    @property
    def localised(self) -> bool:
        """Whether the robot's world pose is known (the simulator's ground truth, or the robot's own
        estimate where the executor steers by one: GoalGenerator.steer_by)."""
        return self.state is not None and self.state.base_pos_w_m is not None

    def require_world_pose(self, goal: TaskGoal) -> None:
        """GoalFailed, before anything moves, when `goal` needs a world pose and there is none."""
        why = world_pose_needed(goal)
        if why is not None and not self.localised:
            raise GoalFailed(f"no world pose for the robot: {why} (a robot reports none and no estimate was given; "
                             "in simulation the simulator gives it); nothing moved for this goal")

    def world_pose(self) -> tuple[RobotState, np.ndarray]:
        """This tick's state and the robot's world position; goals in world coordinates need one."""
        s = self.state
        if s is None or s.base_pos_w_m is None:
            raise GoalFailed("no world pose for the robot (goals in world coordinates need localisation; "
                             "the simulator gives it)")
        return s, s.base_pos_w_m

    def measured_q(self) -> np.ndarray:
        """The robot's configuration now (pinocchio q): joints, IMU orientation, world position (without
        a world pose: the origin; goals that run then need no world: world_pose_needed)."""
        s = self.state
        assert s is not None
        w, x, y, z = s.imu_quat_wxyz
        pos = s.base_pos_w_m if s.base_pos_w_m is not None else np.array([0.0, 0.0, self.poses.nominal_pelvis_m])
        return np.concatenate([pos, [x, y, z, w], s.q_rad])

    def hold_q(self) -> np.ndarray:
        """Where the whole-body reference is now (the end of the current plan)."""
        assert self.plan is not None
        j = self.plan.sample(min(self.t - self.plan_t0, self.plan.duration_s))
        w, x, y, z = j.root_quat_wxyz
        q = np.concatenate([j.root_pos_w_m, [x, y, z, w], j.q_rad])
        if self.overlay is not None:
            q[7 + ARMS] = self.overlay[0].pose(self.t - self.overlay[1])[ARMS]
        return q

    def offset(self) -> np.ndarray:
        """Plan frame minus world (xy): the tracker's odometry drift, measured against the world pose."""
        if self.phase != PHASE_WHOLE_BODY or self.plan is None or not self.localised:
            return np.zeros(2)
        j = self.plan.sample(min(self.t - self.plan_t0, self.plan.duration_s))
        _, pos_w = self.world_pose()
        return j.root_pos_w_m[:2] - pos_w[:2]

    # -- plans --------------------------------------------------------------------------------------
    def run(self, traj: WholeBodyTrajectory, keep: bool = False) -> Iterator[None]:
        self.plan, self.plan_t0 = traj, self.t
        if self.goal is not None:  # what the goal is doing (g1 bench objects names a fall's stage); idle
            self.info["stage"] = traj.name  # plans after a goal leave its record as it ended
        self.overlay = None
        self.keep = keep
        self.phase = PHASE_WHOLE_BODY
        while self.t - self.plan_t0 < traj.duration_s:
            yield

    def compute(self, what: str, fn: Callable[..., T], *args: Any) -> Generator[None, None, T]:
        """fn(poses, *args) inline, or in the planner process while the loop keeps ticking (the robot
        holds its reference meanwhile); returns its result (use with `yield from`). fn is a function at
        a module's top level (or a PosePlanner method) and args are picklable: the same call runs in
        either place. Records the planning CPU (inline) or wall time (in the planner) under `what`, and
        the plan's window in the loop's time (the goal's `plans`: what, start, end)."""
        t_start = self.t
        if self.planner is None:
            t0 = time.process_time()
            out = fn(self.poses, *args)
            self._record(what, time.process_time() - t0, t_start)
            return out
        start = time.perf_counter()
        future = self.planner.submit(fn, *args)
        while not future.done():
            yield
        self._record(f"{what} (planner process, wall)", time.perf_counter() - start, t_start)
        try:
            return future.result()
        except PlannerDied as exc:  # the robot holds its reference; this goal (and later ones) fail
            raise GoalFailed(f"{what}: {exc}") from exc

    def _record(self, what: str, seconds: float, t_start: float) -> None:
        key = f"{self.goal.goal_id if self.goal else ''} {what}".strip()
        self.plan_cpu_s[key] = self.plan_cpu_s.get(key, 0.0) + seconds
        self.plan_windows.append((key, t_start, self.t))

    def close(self) -> None:
        """Stop the planner process (if any)."""
        if self.planner is not None:
            self.planner.close()
            self.planner = None
