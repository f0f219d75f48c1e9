"""`g1 bench stairs`: the whole-body controller (tracker.type wbc, its own gait from a velocity
command) walking straight into stairs and a platform it finds in the scene, approached at seeded
angles and side offsets. Every figure is from the simulator's ground truth.

Courses (the structure's near edge 1.0 m ahead of the robot's start, turned by the drawn angle
about the point on that edge in front of the drawn offset; the robot walks +x and knows only what
the scene says):
  stairs    three 0.15 m treads up (0.45 m deep), a 1.2 m landing at 0.45 m, three treads down;
  platform  one 0.20 m platform, 1.2 m deep, up and down the far side;
  step      one 0.15 m platform, 1.2 m deep, up and down (what the gait does today).

Per trial: fell (the pelvis below 0.45 m above the ground under it, a fall the loop saw, or any
safety trip: a trip counts as a failure), top (both soles on the structure's highest level at
once), across (both soles back on the floor beyond the structure); and, of the controller itself,
its CoP jumps (CopJumps: ticks whose CoP asked moved more than COP_JUMP_M within one contact phase)
and the CPU time (thread time) of its act() each tick, per course beside pinocchio RNEA + CRBA on the
controller's visited states in the same run (the terrain's footholds are searched inside act()).
Draws: angle uniform in +-25 deg, offset uniform in +-0.3 m, from numpy's default_rng(seed).

    g1 bench stairs --seed 100 --trials 10              # seeds 100..109, both courses
    g1 bench stairs --only platform --seed 100 --trials 5
    g1 bench stairs --only step --seed 100 --trials 10
    g1 bench stairs --only stairs --seed 0 --trials 1 --trace /tmp/trace   # per-tick CSV per trial
"""

from __future__ import annotations

import json
import math
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

from g1_control.scene import Platform, SceneConfig

COURSES = ("stairs", "platform", "step")
TRACKER_HZ = 250.0
"""The controller's rate in every trial."""
NEAR_EDGE_M = 1.0
MAX_ANGLE_DEG = 25.0
MAX_OFFSET_M = 0.3
WIDTH_M = 1.4
FALL_PELVIS_M = 0.45
"""Pelvis above the ground under it, below which the robot has fallen (it walks at ~0.70 m)."""
SOLE_BELOW_ANKLE_M = 0.034
"""The ankle-roll body's origin above the sole, standing (measured in the G1 model)."""
COP_JUMP_M = 0.03
"""A CoP asked that moves more than this in one 250 Hz tick (7.5 m/s) within a contact phase jumps:
the gait's CoP moves a few millimetres a tick; only a change of stance or swing foot moves it further."""


class CopJumps:
    """Counts the controller's ticks whose CoP asked (the gait's target, the tracker's view) moved more
    than jump_m from the tick before while the contact phase (the gait's mode, stance foot and swing
    foot) stayed the same. Stop 48 found the CoP asked jumping between the stance sole's two ends every
    tick through a step onto a tread, and MuJoCo's measured CoP with it (the gait's plan moved with the
    landing the terrain snapped, and that landing with the CoP: a loop with a gain above 1); the count
    makes such chatter visible beside the outcomes."""

    def __init__(self, jump_m: float = COP_JUMP_M):
        self.jump_m = jump_m
        self.jumps = 0
        self.ticks = 0
        self._last: tuple[object, np.ndarray] | None = None

    def update(self, phase: object, cop_xy: np.ndarray) -> None:
        cop = np.array(cop_xy, dtype=float)[:2]
        last = self._last
        if last is not None and last[0] == phase:
            self.ticks += 1
            if float(np.hypot(*(cop - last[1]))) > self.jump_m:
                self.jumps += 1
        self._last = (phase, cop)


def course_scene(course: str, angle_rad: float, offset_m: float) -> tuple[SceneConfig, float, float]:
    """(scene, top height, far end along the course's axis from its near edge)."""
    if course == "stairs":
        # (centre along the axis from the near edge, depth, height)
        treads = [(0.225, 0.45, 0.15), (0.675, 0.45, 0.30), (1.5, 1.2, 0.45), (2.325, 0.45, 0.30), (2.775, 0.45, 0.15)]
        far = 3.0
    elif course in ("platform", "step"):
        treads = [(0.6, 1.2, 0.20 if course == "platform" else 0.15)]
        far = 1.2
    else:
        raise ValueError(f"unknown course {course!r}; known: {', '.join(COURSES)}")
    c, s = math.cos(angle_rad), math.sin(angle_rad)
    origin = np.array([NEAR_EDGE_M, offset_m])
    platforms = []
    for i, (along, depth, height) in enumerate(treads):
        centre = origin + along * np.array([c, s])
        platforms.append(Platform(f"{course}_{i}", (float(centre[0]), float(centre[1])), (depth, WIDTH_M), height,
                                  yaw_rad=angle_rad))
    return SceneConfig(platforms=platforms), max(t[2] for t in treads), far


@dataclass
class StairsTrial:
    course: str
    seed: int
    angle_deg: float
    offset_m: float
    fell: bool
    top: bool
    across: bool
    detail: str
    sim_s: float
    wall_s: float
    cop_jumps: int = 0
    """Ticks whose CoP asked jumped (CopJumps) ..."""
    cop_ticks: int = 0
    """... of the ticks that stayed in their contact phase."""
    act_cpu_us: list[float] = field(default_factory=list, repr=False)
    """The controller's act() each tick: thread CPU time (us)."""
    states: list[tuple[np.ndarray, np.ndarray]] = field(default_factory=list, repr=False)
    """(q, v) of the controller every 10th tick: the RNEA + CRBA baseline's inputs."""

    @property
    def success(self) -> bool:
        return self.top and self.across and not self.fell


def draw(seed: int) -> tuple[float, float]:
    rng = np.random.default_rng(seed)
    return float(rng.uniform(-MAX_ANGLE_DEG, MAX_ANGLE_DEG)), float(rng.uniform(-MAX_OFFSET_M, MAX_OFFSET_M))


TRACE_COLUMNS = ("t_s", "mode", "stance", "swing_foot", "swing_progress",
                 "left_along_m", "left_z_m", "right_along_m", "right_z_m",
                 "swing_ref_along_m", "swing_ref_z_m", "landing_z_m", "dcm_error_m",
                 "com_z_m", "com_ref_z_m", "dcm_along_m", "dcm_across_m", "cop_along_m", "cop_across_m",
                 "pelvis_above_ground_m", "fastest_joint", "speed_fraction")
"""`--trace` columns, every 0.02 s. Soles (along the course's axis from its near edge, and height),
the pelvis above the ground under it and the fastest joint (|dq| over its velocity limit) are the
simulator's ground truth; the rest is the controller's own view (odometry frame): its gait's phase,
swing reference and landing height, the DCM's distance from its plan, the CoM's height and target,
the DCM and the CoP asked relative to the stance sole (course axes)."""


def _trace_row(t_s: float, tracker, d, soles: np.ndarray, axis: np.ndarray, origin: np.ndarray,
               scene: SceneConfig) -> list:
    """soles: (2, 3) ground-truth sole positions, left then right (run_course's)."""
    from g1_control.robot import g1

    gait = tracker.gait
    gt = gait.targets
    perp = np.array([-axis[1], axis[0]])
    stance = tracker.sole_positions_m[gait.stance, :2]
    diag = tracker.diagnostics
    dcm, cop = diag.com_ref_m[:2] - stance, gt.cop_xy_m - stance  # walking by its gait, com_ref's xy is the DCM
    speed = np.abs(d.qvel[6:6 + g1.NUM_JOINTS]) / g1.VELOCITY_LIMIT_RADPS
    j = int(np.argmax(speed))
    return [round(t_s, 3), gait.mode, gait.stance, gt.swing_foot, gt.swing_progress,
            float((soles[0][:2] - origin) @ axis), soles[0][2], float((soles[1][:2] - origin) @ axis), soles[1][2],
            float((gt.swing_pos_m[:2] - origin) @ axis), gt.swing_pos_m[2], gt.landing_m[2], gt.dcm_error_m,
            diag.com_m[2], diag.com_ref_m[2], float(dcm @ axis), float(dcm @ perp), float(cop @ axis), float(cop @ perp),
            float(d.qpos[2] - _ground_under(scene, d.qpos[:2])), g1.JOINT_NAMES[j], float(speed[j])]


def run_course(course: str, seed: int, *, speed_mps: float = 0.3, duration_s: float = 40.0,
               trace: list[list] | None = None) -> StairsTrial:
    """Stand 1 s, then walk +x at speed_mps until the robot is across (or falls, or duration_s).
    trace: a list that gets one row (TRACE_COLUMNS) every 0.02 s."""
    import mujoco

    from g1_control.launch.builder import build_loop
    from g1_control.teleop.scripted import Segment
    from g1_control.tools.bench_locomotion import time_act
    from g1_control.tools.physics_trials import Trial, trial_launch

    angle_deg, offset_m = draw(seed)
    scene, top_m, far_m = course_scene(course, math.radians(angle_deg), offset_m)
    trial = Trial(f"stairs_{course}_{seed}", [Segment(1.0, label="stand"),
                                              Segment(duration_s - 1.0, vx_mps=speed_mps, label="walk")],
                  tracker="wbc", tracker_hz=TRACKER_HZ, scene=scene)
    loop = build_loop(trial_launch(trial))
    loop.reset()
    sim = loop.backend
    m, d = sim.model, sim.data  # type: ignore[attr-defined]
    feet = [mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, f"{side}_ankle_roll_link") for side in ("left", "right")]
    axis = np.array([math.cos(math.radians(angle_deg)), math.sin(math.radians(angle_deg))])
    origin = np.array([NEAR_EDGE_M, offset_m])
    top = across = fell = False
    detail = ""
    jumps = CopJumps()
    gait = loop.tracker.gait  # type: ignore[attr-defined]
    cpu: list[float] = []
    states: list[tuple[np.ndarray, np.ndarray]] = []
    time_act(loop.tracker, cpu, states)
    tick_s = 1.0 / trial.tracker_hz
    ticks = round(0.02 / tick_s)
    t0 = time.perf_counter()
    try:
        while loop.time_s < duration_s - 1e-9:
            for _ in range(ticks):  # 0.02 s, a controller tick at a time: the same ticks as one run(0.02)
                loop.run(tick_s)
                jumps.update((gait.mode, gait.stance, gait.targets.swing_foot), gait.targets.cop_xy_m)
            soles = np.array([d.xpos[f] for f in feet])
            soles[:, 2] -= SOLE_BELOW_ANKLE_M
            if trace is not None:
                trace.append(_trace_row(loop.time_s, loop.tracker, d, soles, axis, origin, scene))
            on_top = all(abs(z - top_m) < 0.03 for z in soles[:, 2])
            top = top or on_top
            beyond = all(float((p[:2] - origin) @ axis) > far_m for p in soles)
            if top and beyond and all(abs(z) < 0.03 for z in soles[:, 2]):
                across = True
            ground = _ground_under(scene, d.qpos[:2])
            if loop.fell or loop.faulted or d.qpos[2] - ground < FALL_PELVIS_M:
                fell = True
                detail = str(loop.fall) if loop.fall is not None else (
                    "safety trip" if loop.faulted else f"pelvis {d.qpos[2] - ground:.2f} m above the ground")
                if loop.faulted and loop.fall is None:
                    trips = [e for e in loop.events if getattr(e, "trips", False)]
                    detail = trips[0].detail if trips else detail
                break
            if across:
                break
    finally:
        wall = time.perf_counter() - t0
        sim.close()
    return StairsTrial(course, seed, angle_deg, offset_m, fell, top, across, detail, float(loop.time_s), wall,
                       jumps.jumps, jumps.ticks, cpu, states)


def _write_trace(path: Path, rows: list[list]) -> None:
    import csv

    path.parent.mkdir(parents=True, exist_ok=True)
    with path.open("w", newline="") as f:
        out = csv.writer(f)
        out.writerow(TRACE_COLUMNS)
        out.writerows([f"{v:.4f}" if isinstance(v, float) else v for v in row] for row in rows)


def _ground_under(scene: SceneConfig, xy: np.ndarray) -> float:
    return scene.ground_height(np.asarray(xy, dtype=float))


def main(args) -> int:
    courses = [c for c in COURSES if not args.only or any(c.startswith(p) for p in args.only.split(","))]
    first = int(args.seed)
    count = int(getattr(args, "trials", 5) or 5)
    rows: list[StairsTrial] = []
    print(f"g1 bench stairs: tracker wbc, vx 0.3 m/s, seeds {first}..{first + count - 1}, angle +-{MAX_ANGLE_DEG:.0f} deg, "
          f"offset +-{MAX_OFFSET_M} m (ground truth)")
    print(f"{'course':9s} {'seed':>4s} {'angle':>7s} {'offset':>7s} {'top':>4s} {'across':>6s} {'fell':>4s} "
          f"{'CoP jumps':>9s}  detail")
    for course in courses:
        for seed in range(first, first + count):
            trace: list[list] | None = [] if getattr(args, "trace", None) else None
            r = run_course(course, seed, trace=trace)
            rows.append(r)
            if trace is not None:
                _write_trace(Path(args.trace) / f"{course}_{seed}.csv", trace)
            print(f"{r.course:9s} {r.seed:4d} {r.angle_deg:6.1f}° {r.offset_m:6.2f}m {str(r.top)[0]:>4s} "
                  f"{str(r.across)[0]:>6s} {str(r.fell)[0]:>4s} {r.cop_jumps:9d}  {r.detail}  ({r.sim_s:.1f} s sim, "
                  f"{r.wall_s:.0f} s wall)",
                  flush=True)
    from g1_control.tools.bench_locomotion import rnea_crba_cpu_us

    base50, _ = rnea_crba_cpu_us([s for r in rows for s in r.states])
    tick_us = 1e6 / TRACKER_HZ
    for course in courses:
        sel = [r for r in rows if r.course == course]
        p50, p99 = (float(v) for v in np.percentile([c for r in sel for c in r.act_cpu_us], [50, 99]))
        print(f"{course}: {sum(r.success for r in sel)}/{len(sel)} up and down, top reached {sum(r.top for r in sel)}/"
              f"{len(sel)}, falls {sum(r.fell for r in sel)}/{len(sel)}; CoP jumps {sum(r.cop_jumps for r in sel)} in "
              f"{sum(r.cop_ticks for r in sel)} ticks (> {COP_JUMP_M * 100:.0f} cm in a tick within a contact phase); "
              f"act() CPU p50 {p50:.0f} us ({p50 / base50:.0f}x RNEA+CRBA), p99 {p99:.0f} us = "
              f"{p99 / tick_us * 100:.0f} % of the {tick_us / 1e3:.0f} ms tick")
    print(f"baseline, same run: pinocchio RNEA + CRBA on the controller's visited states: p50 {base50:.1f} us (thread CPU)")
    if args.json:
        Path(args.json).write_text(json.dumps(
            [{**{k: v for k, v in asdict(r).items() if k not in ("act_cpu_us", "states")}, "success": r.success,
              "act_cpu_p50_us": float(np.percentile(r.act_cpu_us, 50)) if r.act_cpu_us else math.nan,
              "act_cpu_p99_us": float(np.percentile(r.act_cpu_us, 99)) if r.act_cpu_us else math.nan}
             for r in rows], indent=1))
    return 1 if any(r.fell for r in rows) else 0


__all__ = ["COP_JUMP_M", "COURSES", "TRACE_COLUMNS", "CopJumps", "StairsTrial", "course_scene", "draw", "main", "run_course"]
