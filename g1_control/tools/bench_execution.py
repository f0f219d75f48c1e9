"""`g1 bench execution`: what the generator plans, executed in physics: a fixed, seeded suite,
one table row per behaviour.

    g1 bench execution                         # the whole suite (~10 min simulated)
    g1 bench execution --only walk.carry       # rows whose name starts with a prefix
    g1 bench execution --json out.json --video videos/
    g1 bench execution --jobs 2                # trials in 2 processes: the same figures
    g1 bench execution --ray local             # or on a Ray cluster (local, local:CPUS, HOST:PORT)

Columns (all from the simulator's ground truth, never from the stack's own labels):
  success   trials that met the row's goal / trials
  falls     trials with a fall (g1_control/safety/fall.py: tilt, pelvis low, a body other than the
            feet on the ground)
  vel err   worst |achieved - commanded| / |commanded| on the commanded axes, % (steady state:
            2 s skipped, whole 1 s gait cycles averaged)
  drift     worst off-axis speed (m/s or rad/s) where the command is zero
  ub rms    upper body (waist + arms) measured vs the tracker's reference posture, rad RMS, worst trial
  hand/obj  hand and object errors (rows that have hands or objects to judge)
  rtf       the full loop's real-time factor in lockstep (simulated / wall seconds)

A row is a Behaviour: a name, a goal, and the trials it runs (g1_control/tools/physics_trials.py);
more rows (reach, box, step) are more entries in `behaviours()`. The last row is the tracking
layer's cost per 50 Hz tick (p50/p99 over every trial's ticks, and its margin to the tick).
The bench exits 1 when a trial fell or a row missed its goal.

Every trial is a task (TrialTask: behaviour, seed, trial number) that a worker turns into its
outcome alone (`run_task`), so `--jobs` and `--ray` (g1_control/fanout.py) change the wall time and
nothing else; `--json` lists every trial's ground-truth figures under `trials` to compare runs.
"""

from __future__ import annotations

import dataclasses
import json
import math
import os
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from g1_control.fanout import describe, fan_out
from g1_control.generator.styles import ROLLOUT_STYLES
from g1_control.report.verdict import Verdict, figures
from g1_control.teleop.scripted import Segment
from g1_control.tools.physics_trials import Push, Trial, TrialResult, run_trial, walk_timeline

WALK_COMMANDS: dict[str, tuple[float, float, float]] = {
    "vx0.5": (0.5, 0.0, 0.0), "vy0.2": (0.0, 0.2, 0.0), "wz0.5": (0.0, 0.0, 0.5), "vx0.4+wz0.3": (0.4, 0.0, 0.3)}
SPEED_TOLERANCE_PCT = 15.0
DRIFT_TOLERANCE = 0.075
"""Off-axis speed allowed where the command is zero (m/s, rad/s): 15 % of 0.5."""
UPPER_BODY_TOLERANCE_RAD = 0.1
HEIGHT_TOLERANCE_M = 0.03
PUSH_N = 100.0
PUSH_S = 0.2
PUSH_DIRECTIONS = {"front": (-1.0, 0.0), "back": (1.0, 0.0), "left": (0.0, -1.0), "right": (0.0, 1.0)}
"""A push "from the front" pushes the robot backwards (heading frame)."""
PUSH_PHASES = 5
"""Pushes per direction, at seeded times spread over one gait cycle."""
TICK_S = 0.02


@dataclass
class Behaviour:
    name: str
    goal: str
    trials: Callable[[int], list[Trial]]
    """seed -> the trials."""
    judge: Callable[[TrialResult], Verdict]
    min_success: float = 1.0
    """Fraction of trials that must succeed."""


@dataclass
class Row:
    behaviour: str
    goal: str
    trials: int
    successes: int
    falls: int
    velocity_error_pct: float | None
    drift: float | None
    upper_body_rms_rad: float | None
    hand_error_m: float | None
    object_error_m: float | None
    real_time_factor: float
    met: bool
    notes: list[str] = field(default_factory=list)
    video: str | None = None


# -- judges ----------------------------------------------------------------------------------------
def velocity_figures(result: TrialResult, index: int, command: tuple[float, float, float]) -> tuple[float, float]:
    """(worst error % on the commanded axes, worst off-axis speed) over segment `index`."""
    v = result.velocity(index)
    errors = [100.0 * abs(v[i] - c) / abs(c) for i, c in enumerate(command) if c != 0.0]
    drift = [abs(v[i]) for i, c in enumerate(command) if c == 0.0]
    return max(errors, default=0.0), max(drift, default=0.0)


def judge_walk(command: tuple[float, float, float], height_m: float | None = None,
               height_tolerance_m: float = HEIGHT_TOLERANCE_M) -> Callable[[TrialResult], Verdict]:
    def judge(result: TrialResult) -> Verdict:
        if result.fell:
            return Verdict(False, f"fell: {result.fall}")
        err, drift = velocity_figures(result, 1, command)
        ub = result.upper_body_rms(1)
        ok = err <= SPEED_TOLERANCE_PCT and drift <= DRIFT_TOLERANCE and ub <= UPPER_BODY_TOLERANCE_RAD
        v = result.velocity(1)
        note = f"v ({v[0]:+.2f}, {v[1]:+.2f}, {v[2]:+.2f})"
        if height_m is not None:
            z = result.pelvis_height(1)
            ok = ok and abs(z - height_m) <= height_tolerance_m
            note += f", pelvis {z:.3f} m (asked {height_m:.2f})"
        return Verdict(bool(ok), note, figures(velocity_error_pct=err, drift=drift, upper_body_rms_rad=ub))
    return judge


def judge_survive(result: TrialResult) -> Verdict:
    return Verdict(not result.fell, f"fell: {result.fall}" if result.fell else "")


# -- the suite ---------------------------------------------------------------------------------------
def push_trials(walking: bool, seed: int) -> list[Trial]:
    """4 directions x PUSH_PHASES pushes of PUSH_N for PUSH_S on the pelvis, at seeded times
    spread over one gait cycle after the gait settled (4 s in), watched for 3 s."""
    rng = np.random.default_rng(seed + (1 if walking else 0))
    command = (0.3, 0.0, 0.0) if walking else (0.0, 0.0, 0.0)
    trials = []
    for direction, (fx, fy) in PUSH_DIRECTIONS.items():
        offsets = (np.arange(PUSH_PHASES) + rng.uniform(0.0, 1.0, PUSH_PHASES)) / PUSH_PHASES * 1.0
        for k, offset in enumerate(offsets):
            t_push = round(4.0 + float(offset), 2)
            trials.append(Trial(f"push {'walk' if walking else 'stand'} {direction} {k}",
                                walk_timeline("default", command, walk_s=t_push + 3.0 - 1.0),
                                pushes=[Push(t_push, (fx * PUSH_N, fy * PUSH_N, 0.0), PUSH_S)]))
    return trials


CROUCH_HEIGHT_M = 0.65


def _walk_trials(style: str, label: str, command: tuple[float, float, float]) -> Callable[[int], list[Trial]]:
    return lambda seed: [Trial(f"walk {style} {label}", walk_timeline(style, command))]


def behaviours() -> list[Behaviour]:
    rows = []
    for style in ROLLOUT_STYLES:
        for label, command in WALK_COMMANDS.items():
            rows.append(Behaviour(
                f"walk.{style}.{label}", f"within {SPEED_TOLERANCE_PCT:.0f} %, drift <= {DRIFT_TOLERANCE}, "
                f"ub <= {UPPER_BODY_TOLERANCE_RAD} rad, no fall", _walk_trials(style, label, command), judge_walk(command)))
    crouch = (0.3, 0.0, 0.0)
    rows.append(Behaviour(
        "crouch_walk.0.65m.vx0.3", f"pelvis within {HEIGHT_TOLERANCE_M * 100:.0f} cm of {CROUCH_HEIGHT_M} m, "
        f"speed within {SPEED_TOLERANCE_PCT:.0f} %, no fall",
        lambda seed: [Trial("crouch walk", [Segment(3.0, label="crouch", pelvis_height_m=CROUCH_HEIGHT_M),
                                            Segment(7.0, vx_mps=crouch[0], label="walk", pelvis_height_m=CROUCH_HEIGHT_M)])],
        judge_walk(crouch, CROUCH_HEIGHT_M)))
    rows.append(Behaviour("push.stand", f"{PUSH_N:.0f} N x {PUSH_S} s from 4 directions: no fall in >= 90 %",
                          lambda seed: push_trials(False, seed), judge_survive, min_success=0.9))
    rows.append(Behaviour("push.walk.vx0.3", f"{PUSH_N:.0f} N x {PUSH_S} s from 4 directions walking at 0.3 m/s: "
                          "no fall in >= 90 %", lambda seed: push_trials(True, seed), judge_survive, min_success=0.9))
    from g1_control.tools.execution_goals import goal_behaviours

    rows += goal_behaviours(Behaviour)
    return rows


# -- running -----------------------------------------------------------------------------------------
def _worst(values: list[float | None]) -> float | None:
    present = [v for v in values if v is not None]
    return max(present) if present else None


@dataclass(frozen=True)
class TrialTask:
    """One trial of the suite, named so that a worker process or a Ray node rebuilds it: the
    behaviour's name, the suite's seed and the trial's place in the behaviour's list."""
    behaviour: str
    seed: int
    index: int
    keep_log: bool = False
    """Send the trial's log back (the driver writes it and renders the behaviour's video)."""


@dataclass
class TrialOutcome:
    """What one trial gives its row: the judge's verdict on ground truth, and the timings."""
    name: str
    verdict: Verdict
    fell: bool
    sim_s: float
    wall_s: float
    tracker_s: np.ndarray | None = None
    """The tracker stage's per-tick seconds (50 Hz policy trials)."""
    layer_cpu: tuple[np.ndarray, np.ndarray] | None = None
    """The tracking layer's per-tick CPU time and what ran (layer trials)."""
    log: dict[str, np.ndarray] | None = None
    end_base_pos_m: tuple[float, float, float] = (math.nan, math.nan, math.nan)
    """Where the pelvis was at the trial's end (simulator ground truth): any difference in the
    physics along the way shows here."""

    def ground_truth(self) -> dict:
        """Everything but the timings: what a run on other machines must reproduce for the same seed."""
        return {"trial": self.name, "ok": self.verdict.ok, "text": self.verdict.text, "values": self.verdict.values,
                "count": self.verdict.count, "met": self.verdict.met(), "fell": self.fell, "sim_s": self.sim_s,
                "end_base_pos_m": list(self.end_base_pos_m)}


def trial_tasks(chosen: list[Behaviour], seed: int, video: bool = False) -> list[TrialTask]:
    """Every trial of the chosen behaviours, in the order the rows print them."""
    return [TrialTask(b.name, seed, i, keep_log=video and i == 0) for b in chosen for i in range(len(b.trials(seed)))]


def trial_outcome(behaviour: Behaviour, trial: Trial, keep_log: bool = False) -> TrialOutcome:
    samples: list[np.ndarray] = []
    result = run_trial(trial, samples=samples if trial.tracker != "layer" else None)
    pos = result.log.get("base_pos_m") if result.log else None
    end = (float(pos[-1][0]), float(pos[-1][1]), float(pos[-1][2])) if pos is not None and len(pos) else (math.nan,) * 3
    return TrialOutcome(trial.name, behaviour.judge(result), bool(result.fell), result.sim_s, result.wall_s,
                        samples[0] if samples else None, result.layer_cpu, result.log if keep_log else None,
                        end)


def run_task(task: TrialTask) -> TrialOutcome:
    """One trial, from its task alone (what `--jobs` processes and Ray workers run)."""
    by_name = {b.name: b for b in behaviours()}
    if task.behaviour not in by_name:
        raise KeyError(f"no behaviour {task.behaviour!r} in the execution suite")
    behaviour = by_name[task.behaviour]
    return trial_outcome(behaviour, behaviour.trials(task.seed)[task.index], task.keep_log)


def make_row(behaviour: Behaviour, outcomes: list[TrialOutcome], video_dir: Path | None = None) -> Row:
    """The row of `behaviour` from its trials' outcomes (in trial order); the first trial's log, when
    it came back, is written into `video_dir` and rendered."""
    verdicts = [o.verdict for o in outcomes]
    sim_s = sum(o.sim_s for o in outcomes)
    wall_s = sum(o.wall_s for o in outcomes)
    video = None
    if video_dir is not None and outcomes and outcomes[0].log is not None:
        from g1_control.sim.render import render_video

        log_path = video_dir / f"{behaviour.name}.npz"
        log_path.parent.mkdir(parents=True, exist_ok=True)
        np.savez_compressed(log_path, **outcomes[0].log)  # type: ignore[arg-type]
        out = log_path.with_suffix(".mp4")
        video = str(out) if render_video(log_path, out, fps=15, size=(480, 360), quiet=True) else None
    successes = sum(v.met() for v in verdicts)
    count = sum(v.count for v in verdicts)
    notes = [f"{o.name}: {o.verdict.text}" for o in outcomes
             if o.verdict.text and (not o.verdict.ok or len(outcomes) == 1)]

    def worst(name: str) -> float | None:
        return _worst([v.values.get(name) for v in verdicts])

    return Row(
        behaviour.name, behaviour.goal, count, successes, sum(o.fell for o in outcomes),
        worst("velocity_error_pct"), worst("drift"), worst("upper_body_rms_rad"), worst("hand_error_m"),
        worst("object_error_m"), sim_s / wall_s if wall_s > 0 else math.inf,
        successes >= math.ceil(behaviour.min_success * count - 1e-9), notes, video)


def run_behaviour(behaviour: Behaviour, seed: int = 0, video_dir: Path | None = None,
                  timings: list[np.ndarray] | None = None,
                  layer_cpu: list[tuple[np.ndarray, np.ndarray]] | None = None) -> Row:
    """Run every trial of `behaviour` here, one after another; `timings` collects the tracker
    stage's per-tick seconds (50 Hz trials), `layer_cpu` the tracking layer's per-tick CPU time and
    what ran (layer trials)."""
    outcomes = [trial_outcome(behaviour, trial, keep_log=video_dir is not None and i == 0)
                for i, trial in enumerate(behaviour.trials(seed))]
    _collect(outcomes, timings, layer_cpu)
    return make_row(behaviour, outcomes, video_dir)


def _collect(outcomes: list[TrialOutcome], timings: list[np.ndarray] | None,
             layer_cpu: list[tuple[np.ndarray, np.ndarray]] | None) -> None:
    for o in outcomes:
        if timings is not None and o.tracker_s is not None:
            timings.append(o.tracker_s)
        if layer_cpu is not None and o.layer_cpu is not None:
            layer_cpu.append(o.layer_cpu)


def run_rows(chosen: list[Behaviour], seed: int = 0, *, jobs: int = 1, ray: str | None = None,
             video_dir: Path | None = None, timings: list[np.ndarray] | None = None,
             layer_cpu: list[tuple[np.ndarray, np.ndarray]] | None = None,
             outcomes: list[TrialOutcome] | None = None) -> Iterator[Row]:
    """The rows of `chosen`, each as soon as its trials are done, with every trial fanned out over
    `jobs` processes or the Ray cluster at `ray` (g1_control/fanout.py); the same rows for the same
    seed however they ran (timings aside). `outcomes` gets every trial's outcome, in order."""
    tasks = trial_tasks(chosen, seed, video_dir is not None)
    counts = {b.name: 0 for b in chosen}
    for task in tasks:
        counts[task.behaviour] += 1
    by_name = {b.name: b for b in chosen}
    pending: list[TrialOutcome] = []
    for task, outcome in zip(tasks, fan_out(run_task, tasks, jobs=jobs, ray=ray), strict=True):
        pending.append(outcome)
        if outcomes is not None:
            outcomes.append(outcome)
        if len(pending) == counts[task.behaviour]:
            _collect(pending, timings, layer_cpu)
            yield make_row(by_name[task.behaviour], pending, video_dir)
            pending = []


def _fmt(value: float | None, spec: str) -> str:
    return "-" if value is None else format(value, spec)


def format_row(row: Row) -> str:
    return (f"{row.behaviour:<28} {row.successes:>3}/{row.trials:<3} {row.falls:>5} {_fmt(row.velocity_error_pct, '7.1f'):>7} "
            f"{_fmt(row.drift, '6.3f'):>6} {_fmt(row.upper_body_rms_rad, '7.3f'):>7} {_fmt(row.hand_error_m, '6.3f'):>6} "
            f"{_fmt(row.object_error_m, '6.3f'):>6} {row.real_time_factor:5.1f}  {'ok' if row.met else 'MISSED'}")


HEADER = (f"{'behaviour':<28} {'success':>7} {'falls':>5} {'vel err':>7} {'drift':>6} {'ub rms':>7} {'hand':>6} "
          f"{'obj':>6} {'rtf':>5}  goal")


def cost_summary(samples: list[np.ndarray], period_s: float = TICK_S) -> dict:
    """The tracking layer's cost per tick over every trial: p50/p99/max and the margin to the tick."""
    data = np.concatenate(samples) if samples else np.zeros(1)
    p50, p99 = np.percentile(data, [50, 99])
    return {"ticks": int(data.size), "p50_us": float(p50 * 1e6), "p99_us": float(p99 * 1e6),
            "max_us": float(data.max() * 1e6), "margin_p99": float(period_s / p99) if p99 > 0 else math.inf}


def layer_cost(repeats: int = 3) -> dict:
    """The styled tracker's act() per 50 Hz tick against the same policy tracker without the
    upper-body override (the baseline: what the bare policy costs), on the states and plans of a
    styled walk (carry, vx 0.4 + wz 0.3), calls interleaved so that machine load hits both alike.
    Wall time per call, and the thread's CPU time per call (what the code itself costs, without
    the time other processes on a loaded machine take from it)."""
    import time

    from g1_control.trackers.locomotion import LocomotionPolicyTracker
    from g1_control.trackers.policy_spec import load_spec
    from g1_control.types import JointReference, RobotState

    log = run_trial(Trial("cost", walk_timeline("carry", WALK_COMMANDS["vx0.4+wz0.3"]))).log
    spec = load_spec("holosoma_loco_ppo")
    trackers = {True: LocomotionPolicyTracker(spec), False: LocomotionPolicyTracker(spec)}
    dq = np.gradient(log["q_rad"], TICK_S, axis=0)
    ticks = []
    for k in range(len(log["t_s"])):
        state = RobotState(t_s=float(log["t_s"][k]), q_rad=log["q_rad"][k].copy(), dq_radps=dq[k],
                           imu_quat_wxyz=log["base_quat_wxyz"][k].copy())
        refs = {styled: JointReference(q_rad=log["q_ref_rad"][k].copy(), upper_body_override=styled,
                                       root_linvel_h_mps=np.array([*log["command"][k][:2], 0.0]),
                                       root_angvel_h_radps=np.array([0.0, 0.0, log["command"][k][2]]))
                for styled in (True, False)}
        ticks.append((state, refs))
    wall: dict[bool, list[float]] = {True: [], False: []}
    cpu: dict[bool, list[float]] = {True: [], False: []}
    for _ in range(repeats):
        for tracker in trackers.values():
            tracker.reset(ticks[0][0])
        for state, refs in ticks:
            for styled in (True, False):
                t0, c0 = time.perf_counter(), time.thread_time()
                trackers[styled].act(refs[styled], state)
                cpu[styled].append(time.thread_time() - c0)
                wall[styled].append(time.perf_counter() - t0)
    out: dict = {}
    for styled, name in ((True, "styled"), (False, "bare")):
        p50, p99 = np.percentile(np.array(wall[styled]) * 1e6, [50, 99])
        c50, c99 = np.percentile(np.array(cpu[styled]) * 1e6, [50, 99])
        out[name] = {"p50_us": float(p50), "p99_us": float(p99), "cpu_p50_us": float(c50), "cpu_p99_us": float(c99)}
    out["margin_p99"] = TICK_S * 1e6 / out["styled"]["p99_us"]
    out["margin_cpu_p99"] = TICK_S * 1e6 / out["styled"]["cpu_p99_us"]
    out["ticks"] = len(wall[True])
    return out


def main(args) -> int:
    started = time.perf_counter()
    only = getattr(args, "only", None)
    seed = int(getattr(args, "seed", 0) or 0)
    video_dir = Path(args.video) if getattr(args, "video", None) else None
    chosen = [b for b in behaviours() if not only or any(b.name.startswith(p) for p in only.split(","))]
    if not chosen:
        print(f"g1 bench execution: no behaviour starts with {only!r}")
        return 2
    jobs, ray = int(getattr(args, "jobs", 1) or 1), getattr(args, "ray", None)
    print(f"g1 bench execution: {len(chosen)} behaviours, {sum(len(b.trials(seed)) for b in chosen)} trials, seed "
          f"{seed}, {describe(jobs, ray)}; figures from the simulator's ground truth")
    print(HEADER)
    rows: list[Row] = []
    samples: list[np.ndarray] = []
    layer_cpu: list[tuple[np.ndarray, np.ndarray]] = []
    trials: list[TrialOutcome] = []
    for row in run_rows(chosen, seed, jobs=jobs, ray=ray, video_dir=video_dir, timings=samples, layer_cpu=layer_cpu,
                        outcomes=trials):
        rows.append(row)
        print(format_row(row), flush=True)
    sweep_s = time.perf_counter() - started
    print(f"{len(trials)} trials in {sweep_s:.1f} s wall, {describe(jobs, ray)}")
    cost = cost_summary(samples)
    sim = sum(r.trials for r in rows)
    rtf = [r.real_time_factor for r in rows]
    print(f"\ntracking layer (tracker stage, {cost['ticks']} ticks at 50 Hz): p50 {cost['p50_us']:.0f} us, "
          f"p99 {cost['p99_us']:.0f} us, max {cost['max_us']:.0f} us -> margin {cost['margin_p99']:.1f}x at p99 "
          f"(goal >= 2x); full loop real-time factor {min(rtf):.1f}-{max(rtf):.1f}x over {sim} trials; "
          f"load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    goal_layer = None
    if layer_cpu:
        from g1_control.tools.execution_goals import layer_cpu_summary

        goal_layer = layer_cpu_summary(layer_cpu)
        print(goal_layer["text"])
    layer = layer_cost()
    st, bare = layer["styled"], layer["bare"]
    print(f"tracking layer act() replayed ({layer['ticks']} ticks, interleaved), wall p50/p99: styled "
          f"{st['p50_us']:.0f}/{st['p99_us']:.0f} us, bare policy {bare['p50_us']:.0f}/{bare['p99_us']:.0f} us; "
          f"thread CPU p50/p99: styled {st['cpu_p50_us']:.0f}/{st['cpu_p99_us']:.0f} us, bare "
          f"{bare['cpu_p50_us']:.0f}/{bare['cpu_p99_us']:.0f} us; margin to the 20 ms tick at p99: "
          f"{layer['margin_p99']:.1f}x wall, {layer['margin_cpu_p99']:.0f}x CPU")
    for row in rows:
        for note in row.notes if not row.met else []:
            print(f"  {row.behaviour}: {note}")
    fell = any(r.falls for r in rows)
    missed = [r.behaviour for r in rows if not r.met]
    if args.json:
        Path(args.json).write_text(json.dumps({"seed": seed, "rows": [dataclasses.asdict(r) for r in rows],
                                               "trials": [t.ground_truth() for t in trials],
                                               "run": {"jobs": jobs, "ray": ray, "wall_s": sweep_s},
                                               "tracking_cost": cost, "layer_cost": layer,
                                               "goal_layer_cost": goal_layer,
                                               "load_average_1min": os.getloadavg()[0]}, indent=1))
    if fell or missed:
        print(f"FAILED: {sum(r.falls for r in rows)} trial(s) fell; goals missed: {', '.join(missed) or 'none'}")
        return 1
    return 0
