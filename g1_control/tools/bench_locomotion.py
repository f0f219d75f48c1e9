"""`g1 bench locomotion`: the model-based controller's walking against holosoma's ppo and fastsac
walking policies, in one run, one table: per axis and speed, what the robot achieved against
what was commanded, falls, and the CPU cost of each tracker's act().

Every row is one launch through the one loop builder in lockstep MuJoCo: the velocity generator,
1 s standing, then the command for --seconds (rows forward/backward/sideways/turning);
then pushes (push_<direction>_<k>: PUSH_N for PUSH_S on the pelvis while walking, 4 directions x
PUSH_PHASES points of the stride, one run per push; a push is survived when neither a fall nor a
safety trip follows it within PUSH_SETTLE_S) and 10 seeded random velocity timelines (random_s*: 1-5 s
segments, reversals, combined axes, stops; 30 s each); the WBC (tracker.type wbc, its own gait) at 250 Hz,
the policies (tracker.type policy, their trained command range, not the shipped envelope) at their
50 Hz. Figures, all from the simulator's ground truth:
  achieved   mean heading-frame (vx, vy, wz) over whole gait cycles after the first STEADY_SKIP_S
             of walking (the WBC's stride is two of its steps at the command's cadence; the policies' gait period is 1 s);
  error      achieved minus commanded on a commanded axis, in % of the command (the worst axis);
  off-axis   the largest |achieved| of the uncommanded axes (m/s or rad/s);
  fell       the loop's fall monitor (pelvis below 0.4 m or tilted), and the lowest pelvis height;
  act CPU    p50/p99 of the tracker's act() in thread CPU time (not wall time: the machines are
             shared), beside pinocchio RNEA + CRBA on the WBC's visited states in the same run;
  log_sha256 (JSON only) a digest of the row's per-tick ground truth and motor targets: lockstep rows
             repeat bit for bit, in any order and any process, so two runs of one code agree on it.
Exits 1 when any row fell.

    g1 bench locomotion                          # every row (~15 min)
    g1 bench locomotion --only wbc --seconds 10  # rows whose name starts with a prefix
    g1 bench locomotion --json out.json
"""

from __future__ import annotations

import hashlib
import json
import math
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, cast

import numpy as np

from g1_control.teleop.scripted import Segment

if TYPE_CHECKING:
    from g1_control.robot.g1 import VariantName
    from g1_control.sim.mujoco_backend import MujocoBackend
    from g1_control.sim.randomize import RandomizeConfig

CONTROLLERS: dict[str, tuple[str, str, float]] = {
    "wbc": ("wbc", "", 250.0),
    "ppo": ("policy", "holosoma_loco_ppo", 50.0),
    "fastsac": ("policy", "holosoma_loco_fastsac", 50.0),
}
"""name -> (tracker.type, tracker.policy, tracker rate Hz)."""
POLICY_GAIT_PERIOD_S = 1.0
LOG_DIGEST_FIELDS = ("t_s", "base_pos_m", "base_quat_wxyz", "velocity_true", "q_rad", "q_target_rad", "tau_nm")
"""The per-tick log fields Row.log_sha256 covers: the simulator's ground truth and what was commanded."""


@dataclass(frozen=True)
class Case:
    name: str
    command: tuple[float, float, float]
    """(vx m/s, vy m/s, wz rad/s) in the heading frame."""
    style: str = "default"
    timeline: tuple[Segment, ...] = ()
    """Instead of standing then `command`: this timeline (no steady-state figures then)."""
    pushes: tuple[tuple[float, tuple[float, float, float]], ...] = ()
    """(time s, force N in the heading frame at that time) pushes on the pelvis, PUSH_S each."""
    push_stride_fraction: float = 0.0
    """The pushes come this fraction of the controller's stride later (the point of the gait)."""


CASES = (
    Case("forward_0.5", (0.5, 0.0, 0.0)),
    Case("forward_1.0", (1.0, 0.0, 0.0)),
    Case("backward_0.5", (-0.5, 0.0, 0.0)),
    Case("sideways_0.4", (0.0, 0.4, 0.0)),
    Case("turning_1.2", (0.0, 0.0, 1.2)),
    Case("combined_0.6_0.5", (0.6, 0.0, 0.5)),
    Case("carry_forward_0.5", (0.5, 0.0, 0.0), style="carry"),
    Case("arm_swing_forward_0.5", (0.5, 0.0, 0.0), style="arm_swing"),
)
STEADY_SKIP_S = 3.0
PUSH_S = 0.2
PUSH_N = 150.0
PUSH_SPEED_MPS = 0.5
PUSH_PHASES = 5
PUSH_AT_S = 4.0
PUSH_SETTLE_S = 2.5


def random_cases(n: int = 10, duration_s: float = 30.0) -> tuple[Case, ...]:
    """Seeded random velocity timelines: 1-5 s segments, reversals, combined axes, stops."""
    from g1_control.teleop.scripted import RandomTimelineConfig, random_timeline

    out = []
    for seed in range(n):
        config = RandomTimelineConfig(seed=seed, segment_s=(1.0, 5.0), vx_mps=(-0.5, 0.8), vy_mps=(-0.2, 0.2),
                                      wz_radps=(-1.0, 1.0), stand_probability=0.15)
        out.append(Case(f"random_s{seed}", (0.0, 0.0, 0.0), timeline=tuple(random_timeline(config, duration_s))))
    return tuple(out)


def push_cases(walk_s: float | None = None) -> tuple[Case, ...]:
    """Walking forward at PUSH_SPEED_MPS, one push of PUSH_N for PUSH_S on the pelvis per run, from
    each of 4 directions (named by the side pushed: front pushes backwards) at PUSH_PHASES points of
    the stride (k / PUSH_PHASES of the controller's stride after PUSH_AT_S); each run ends
    PUSH_SETTLE_S after its push (walk_s is not used: the grid's runs are short by design)."""
    out = []
    duration = PUSH_AT_S + 1.0 + PUSH_S + PUSH_SETTLE_S  # the push's latest start is a stride (<= 1 s) on
    for name, force in (("front", (-PUSH_N, 0.0, 0.0)), ("back", (PUSH_N, 0.0, 0.0)),
                        ("left", (0.0, -PUSH_N, 0.0)), ("right", (0.0, PUSH_N, 0.0))):
        for k in range(PUSH_PHASES):
            out.append(Case(f"push_{name}_{k}", (PUSH_SPEED_MPS, 0.0, 0.0),
                            timeline=(Segment(1.0, label="stand"),
                                      Segment(duration - 1.0, vx_mps=PUSH_SPEED_MPS, label="walk")),
                            pushes=((PUSH_AT_S, force),), push_stride_fraction=k / PUSH_PHASES))
    return tuple(out)


@dataclass
class Row:
    controller: str
    case: str
    command: list[float]
    achieved: list[float] = field(default_factory=lambda: [math.nan] * 3)
    error_pct: float = math.nan
    off_axis: float = math.nan
    fell: bool = False
    fall: str = ""
    min_pelvis_m: float = math.nan
    act_cpu_p50_us: float = math.nan
    act_cpu_p99_us: float = math.nan
    sim_s: float = 0.0
    wall_s: float = 0.0
    pushes: int = 0
    pushes_survived: int = 0
    """Pushes followed by neither a fall nor a safety trip within PUSH_SETTLE_S."""
    trip: str = ""
    """The safety layer's first trip (damping), if any: a joint over-speed, say."""
    backend: str = ""
    """The simulated robot (loop.chain's backend: nominal, or the randomisation drawn)."""
    log_sha256: str = ""
    """log_digest of the run: equal for two runs exactly when their logs agree bit for bit."""

    @property
    def name(self) -> str:
        return f"{self.controller}/{self.case}"


def steady_velocity(log: dict[str, np.ndarray], t_from_s: float, t_to_s: float, period_s: float) -> np.ndarray:
    """Mean of the true heading-frame (vx, vy, wz) over whole `period_s` cycles from t_from_s."""
    cycles = math.floor((t_to_s - t_from_s) / period_s + 1e-9)
    if cycles < 1:
        raise ValueError(f"no whole gait cycle of {period_s:.2f} s between {t_from_s:.2f} and {t_to_s:.2f} s")
    t = log["t_s"]
    window = (t >= t_from_s - 1e-9) & (t < t_from_s + cycles * period_s - 1e-9)
    return log["velocity_true"][window].mean(axis=0)


def log_digest(log: dict[str, np.ndarray]) -> str:
    """sha256 over the bytes of a run log's LOG_DIGEST_FIELDS (their names and shapes included)."""
    digest = hashlib.sha256()
    for name in LOG_DIGEST_FIELDS:
        values = np.ascontiguousarray(log[name], dtype=np.float64)
        digest.update(f"{name}{values.shape}".encode())
        digest.update(values.tobytes())
    return digest.hexdigest()


def wbc_stride_s(tracker, command: tuple[float, float, float]) -> float:
    """The WBC's stride (two steps) walking `command` steadily: its cadence rises with speed
    (gait.py, GaitConfig.fast_single_support_s)."""
    from g1_control.trackers.wbc.gait import step_duration_for

    gait = tracker.gait
    return 2 * step_duration_for(gait.config, gait.feasible(np.array(command, dtype=float))[:2])


def case_launch(controller: str, case: Case, walk_s: float, randomize: RandomizeConfig | None = None,
                variant: VariantName | None = None):
    """The launch of one row; `randomize`: on a randomised robot (g1_control/sim/randomize.py);
    `variant`: the robot the simulator builds and the controller models (g1.VARIANTS; None: the launch
    default, the 29-DoF G1)."""
    from g1_control.launch.schema import LaunchFile

    kind, policy, hz = CONTROLLERS[controller]
    vx, vy, wz = case.command
    launch = LaunchFile(name=f"locomotion_{controller}_{case.name}")
    launch.input.timeline = list(case.timeline) or [
        Segment(1.0, style=case.style, label="stand"),
        Segment(walk_s, vx_mps=vx, vy_mps=vy, wz_radps=wz, style=case.style, label="walk")]
    for seg in launch.input.timeline:
        vx, vy, wz = max(abs(vx), abs(seg.vx_mps)), max(abs(vy), abs(seg.vy_mps)), max(abs(wz), abs(seg.wz_radps))
    launch.generator.type = "velocity"
    launch.tracker.type = kind  # type: ignore[assignment]
    if policy:
        launch.tracker.policy = policy
    launch.tracker.envelope_limits = False
    launch.rates.tracker_hz = hz
    launch.limits.max_vx_mps = max(launch.limits.max_vx_mps, abs(vx))
    launch.limits.max_vy_mps = max(launch.limits.max_vy_mps, abs(vy))
    launch.limits.max_wz_radps = max(launch.limits.max_wz_radps, abs(wz))
    launch.backend.randomize = randomize
    if variant is not None:
        launch.backend.expected_variant = variant
    launch.validate("locomotion")
    launch.output.video, launch.output.plot, launch.viewer = False, False, False
    return launch


def run_case(controller: str, case: Case, walk_s: float, states: list | None = None,
             randomize: RandomizeConfig | None = None, variant: VariantName | None = None) -> Row:
    """One row. `states`: gets (q, v) samples of the run appended (the RNEA + CRBA baseline);
    `randomize`: on a randomised robot; `variant`: on that robot variant (case_launch)."""
    from g1_control.launch.builder import build_loop

    loop = build_loop(case_launch(controller, case, walk_s, randomize, variant))
    loop.reset()
    tracker = loop.tracker
    cpu: list[float] = []
    time_act(tracker, cpu, states if controller == "wbc" else None)
    duration = sum(seg.duration_s for seg in case.timeline) if case.timeline else 1.0 + walk_s
    stride = wbc_stride_s(tracker, case.command) if controller == "wbc" else POLICY_GAIT_PERIOD_S
    shifted = tuple((t + case.push_stride_fraction * stride, f) for t, f in case.pushes)
    marks = sorted({t for t, _ in shifted if t < duration} | {duration})
    pushes = dict(shifted)
    t0 = time.perf_counter()
    try:
        for mark in marks:
            loop.scheduler.run(round((mark - loop.time_s) * loop.rates.lowlevel_hz), stop=lambda: loop.fell)
            if loop.fell:
                break
            if mark in pushes:
                from g1_control.tools.physics_trials import heading_to_world

                sim = cast("MujocoBackend", loop.backend)
                sim.push(heading_to_world(pushes[mark], sim.data.qpos[3:7]), PUSH_S)
    finally:
        wall = time.perf_counter() - t0
        loop.backend.close()
    log = loop.log.arrays()
    row = Row(controller, case.name, list(case.command), sim_s=float(loop.time_s), wall_s=wall,
              backend=loop.chain["backend"], log_sha256=log_digest(log))
    row.fell = loop.fell
    row.fall = str(loop.fall) if loop.fall else ""
    trip = next((e for e in loop.events if e.trips and e.kind != "fall"), None)
    row.trip = str(trip) if trip else ""
    row.min_pelvis_m = float(log["base_pos_m"][:, 2].min())
    samples = np.asarray(cpu, dtype=float)
    row.act_cpu_p50_us, row.act_cpu_p99_us = (float(v) for v in np.percentile(samples, [50, 99]))
    if case.pushes:
        # a safety trip (damping) ends the controller's run as surely as a fall
        t_end = min([math.inf] + ([loop.fall.t_s] if loop.fall else []) + [e.t_s for e in loop.events if e.trips])
        row.pushes_survived = sum(1 for t, _ in shifted if t + PUSH_SETTLE_S <= t_end and t < duration)
        row.pushes = len(case.pushes)
    if not row.fell and not case.timeline:
        period = stride
        achieved = steady_velocity(log, 1.0 + STEADY_SKIP_S, duration, period)
        row.achieved = [float(v) for v in achieved]
        errors = [100.0 * (achieved[k] - c) / c for k, c in enumerate(case.command) if c]
        row.error_pct = float(max(errors, key=abs))
        row.off_axis = float(max([abs(achieved[k]) for k, c in enumerate(case.command) if not c], default=0.0))
    return row


def time_act(tracker, cpu_us: list[float], states: list | None = None) -> None:
    """Wrap tracker.act: each call's thread CPU time (us) appended to cpu_us, and, given `states`, the
    WBC's own (q, v) every 10th call (the RNEA + CRBA baseline's inputs, `rnea_crba_cpu_us`)."""
    act = tracker.act

    def timed_act(reference, state):
        t0 = time.thread_time_ns()
        out = act(reference, state)
        cpu_us.append((time.thread_time_ns() - t0) / 1e3)
        if states is not None and len(cpu_us) % 10 == 0:
            states.append((tracker._q.copy(), tracker._v.copy()))
        return out

    tracker.act = timed_act


def rnea_crba_cpu_us(states: list[tuple[np.ndarray, np.ndarray]]) -> tuple[float, float]:
    """p50/p99 thread CPU time (us) of pinocchio RNEA + CRBA on `states` (the WBC's model)."""
    import pinocchio as pin

    from g1_control.robot.dynamics import build_model

    model = build_model()
    data = model.createData()
    a0 = np.zeros(model.nv)
    samples = []
    for q, v in states:
        t0 = time.thread_time_ns()
        pin.rnea(model, data, q, v, a0)
        pin.crba(model, data, q)
        samples.append((time.thread_time_ns() - t0) / 1e3)
    p50, p99 = np.percentile(samples, [50, 99])
    return float(p50), float(p99)


def run_table(controllers: list[str], cases: list[Case], walk_s: float, only: list[str] | None = None,
              echo=print) -> tuple[list[Row], tuple[float, float]]:
    """Every (controller, case) row whose name starts with one of `only` (all when None), and the
    RNEA + CRBA baseline (nan without a WBC row)."""
    rows: list[Row] = []
    states: list = []
    for case in cases:
        for controller in controllers:
            name = f"{controller}/{case.name}"
            if only and not any(name.startswith(p) for p in only):
                continue
            row = run_case(controller, case, walk_s, states)
            rows.append(row)
            echo(format_row(row))
    baseline = rnea_crba_cpu_us(states) if states else (math.nan, math.nan)
    return rows, baseline


HEADER = (f"{'controller/case':<24} {'command':>17} {'achieved':>23} {'error %':>8} {'off-axis':>8} {'fell':>5} "
          f"{'min z m':>7} {'pushes':>6} {'act CPU p50/p99 us':>19}")


def format_row(row: Row) -> str:
    cmd = "({:+.2f} {:+.2f} {:+.2f})".format(*row.command)
    got = "({:+.3f} {:+.3f} {:+.3f})".format(*row.achieved) if np.isfinite(row.achieved).all() else "-"
    if row.case.startswith("random"):
        cmd = "random timeline"
    pushes = f"{row.pushes_survived}/{row.pushes}" if row.pushes else "-"
    return (f"{row.name:<24} {cmd:>17} {got:>23} {row.error_pct:8.1f} {row.off_axis:8.3f} "
            f"{'FELL' if row.fell else 'TRIP' if row.trip else 'no':>5} {row.min_pelvis_m:7.3f} {pushes:>6} "
            f"{row.act_cpu_p50_us:9.0f}/{row.act_cpu_p99_us:<9.0f}")


def main(args) -> int:
    only = [p for p in (args.only or "").split(",") if p] or None
    walk_s = float(args.seconds)
    print(f"g1 bench locomotion: {walk_s:.0f} s per row after 1 s standing; achieved = ground-truth mean over whole "
          f"gait cycles after {STEADY_SKIP_S:.0f} s of walking; act() in thread CPU time")
    from g1_control.tools.environment import describe, environment

    env = environment()
    print(describe(env))
    print(HEADER, flush=True)
    cases = [*CASES, *push_cases(walk_s), *random_cases()]
    rows, (base50, base99) = run_table(list(CONTROLLERS), cases, walk_s, only,
                                       echo=lambda line: print(line, flush=True))
    print(f"baseline, same run: pinocchio RNEA + CRBA on the WBC's visited states: p50 {base50:.0f} us, "
          f"p99 {base99:.0f} us (thread CPU)")
    for row in rows:
        if row.controller == "wbc" and np.isfinite(base50):
            print(f"  {row.name}: act()/RNEA+CRBA p50 {row.act_cpu_p50_us / base50:.1f}x; p99 {row.act_cpu_p99_us:.0f} us "
                  f"= {row.act_cpu_p99_us / 4000 * 100:.0f} % of the 4 ms tick at 250 Hz")
    for controller in CONTROLLERS:
        pushed = [r for r in rows if r.controller == controller and r.pushes]
        randoms = [r for r in rows if r.controller == controller and r.case.startswith("random")]
        if pushed or randoms:
            print(f"  {controller}: pushes survived {sum(r.pushes_survived for r in pushed)}/"
                  f"{sum(r.pushes for r in pushed)} ({PUSH_N:.0f} N x {PUSH_S} s walking {PUSH_SPEED_MPS} m/s); "
                  f"random timelines without a fall {sum(not r.fell for r in randoms)}/{len(randoms)}")
    falls = [row.name for row in rows if row.fell]
    if falls:
        print(f"FELL: {', '.join(falls)}")
    if args.json:
        Path(args.json).write_text(json.dumps({"walk_s": walk_s, "steady_skip_s": STEADY_SKIP_S, "environment": env,
                                               "rnea_crba_cpu_p50_us": base50, "rnea_crba_cpu_p99_us": base99,
                                               "rows": [asdict(r) for r in rows]}, indent=2))
    return 1 if falls else 0
