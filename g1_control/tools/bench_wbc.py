"""`g1 bench wbc`: the whole-body controller's cost per control tick, against baselines measured
in the same run on the same states.

The walk: `tracker.type: wbc` with the velocity generator, 1 s standing then 0.3 m/s forward for
the rest of --seconds (the controller's own gait, trackers/wbc/gait.py), in lockstep MuJoCo through
the one loop builder. The walk's figures come from the simulator's ground truth: fell or not
(safety/fall.py), the forward and sideways speed and the yaw rate over whole strides after 3 s.

Figures:
  - QP solve time p50/p99 per tick (proxsuite, warm-started), over the closed-loop walk
    (contact switches included); goal p99 <= 1 ms so the controller could run at 500 Hz;
  - the whole act() (estimator, odometry, dynamics, tasks, QP) p50/p99;
  - baselines on the states the run visited: pinocchio RNEA + CRBA alone (the least any
    model-based controller computes per tick), and the same QPs (every 8th tick's) solved cold
    by a fresh solver (setup included, as a controller without warm start would pay);
  - real-time factor of the whole loop with the WBC at 250 Hz, against stepping the same MuJoCo
    model alone for the same simulated time;
  - the warm starts: the walk's first REPLAY_TICKS problems solved again, in order, by a solver that
    carries its proximal parameters over (the default) and by one that resets them when a foot's contact
    rows change (QpConfig.contact_change_mu_in = RESET_MU_IN, off by default), alternately, best of
    REPLAY_ROUNDS: the warm starts that exited unsolved (carried over: then solved cold next tick, as the
    tracker's retry starts a fresh solver), iterations and solve time.
"""

from __future__ import annotations

import json
import os
import time
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, cast
from unittest import mock

import numpy as np

if TYPE_CHECKING:
    from g1_control.trackers.wbc.tracker import WholeBodyTracker

PROBLEM_STRIDE = 8
"""Every 8th tick's QP is kept for the cold-solve baseline."""
WALK_SPEED_MPS = 0.3
STEADY_FROM_S = 3.0
REPLAY_TICKS = 1500
"""The walk's first problems kept for the warm-start replay (each ~56 kB)."""
REPLAY_ROUNDS = 3
RESET_MU_IN = 1e-2


@dataclass
class VelocityWalk:
    sim_s: float
    wall_s: float
    fall: Any
    velocity_h: np.ndarray
    """Ground truth (vx, vy, wz), heading frame, mean over whole strides after STEADY_FROM_S."""
    distance_m: float


def velocity_walk(speed_mps: float, duration_s: float, tracker_hz: float):
    """Stand 1 s, then walk forward at speed_mps until duration_s: tracker.type wbc with the
    velocity generator, lockstep MuJoCo, stopped at a fall. Returns (VelocityWalk, loop)."""
    from g1_control.launch.builder import build_loop
    from g1_control.tools.bench_locomotion import steady_velocity
    from g1_control.tools.physics_trials import Trial, trial_launch, walk_timeline

    trial = Trial("bench_wbc_walk", walk_timeline("default", (speed_mps, 0.0, 0.0), walk_s=duration_s - 1.0),
                  tracker="wbc", tracker_hz=tracker_hz)
    loop = build_loop(trial_launch(trial))
    loop.reset()
    t0 = time.perf_counter()
    loop.scheduler.run(round(duration_s * loop.rates.lowlevel_hz), stop=lambda: loop.fell)
    wall = time.perf_counter() - t0
    log = loop.log.arrays()
    wbc = cast("WholeBodyTracker", loop.tracker)  # what build_loop makes for tracker.type wbc
    try:
        velocity = steady_velocity(log, STEADY_FROM_S, float(loop.time_s), wbc.config.gait.step_s * 2)
    except ValueError:  # fell (or too short) before a whole stride of steady walking
        velocity = np.full(3, np.nan)
    xy = log["base_pos_m"][:, :2]
    return VelocityWalk(float(loop.time_s), wall, loop.fall, velocity,
                        float(np.linalg.norm(xy[-1] - xy[0]))), loop


def _pct(samples_s) -> tuple[float, float]:
    p50, p99 = np.percentile(np.asarray(samples_s) * 1e6, [50, 99])
    return float(p50), float(p99)


def replay_warm_starts(sequence, config, nv: int) -> dict[str, dict[str, Any]]:
    """The problems of `sequence` (H, g, A, b, C, l, u per tick) solved in order by the controller's QP
    with the proximal parameters carried over ("carried_over") and reset on contact changes ("reset"),
    alternately for REPLAY_ROUNDS rounds: the best time per problem, the iterations and the warm starts
    that exited unsolved in the first round."""
    from dataclasses import replace

    from g1_control.trackers.wbc.qp import InverseDynamicsQP

    configs = {"carried_over": replace(config, contact_change_mu_in=None),
               "reset": replace(config, contact_change_mu_in=RESET_MU_IN)}
    out: dict[str, dict[str, Any]] = {}
    for round_ in range(REPLAY_ROUNDS):
        for name, cfg in configs.items():
            qp = InverseDynamicsQP(nv, cfg)
            mats = (qp.H, qp.g, qp.A, qp.b, qp.C, qp.l, qp.u)
            times, iterations = [], []
            for problem in sequence:
                for dst, src in zip(mats, problem):
                    dst[...] = src
                solved, iters, seconds = qp.solve_problem()
                if not solved:
                    qp.reset()  # as the tracker does: the next solve starts cold
                times.append(seconds * 1e6)
                iterations.append(iters)
            if round_ == 0:
                out[name] = {"solve_us": np.array(times), "iterations": iterations, "warm_exits": qp.warm_exits}
            else:
                np.minimum(out[name]["solve_us"], times, out=out[name]["solve_us"])
    return out


def main(args) -> int:
    import pinocchio as pin

    from g1_control.tools.bench_loop import physics_only_seconds
    from g1_control.tools.wbc_evaluate import DEFAULT_TRACKER_HZ
    from g1_control.trackers.wbc import tracker as tracker_module

    seconds = float(args.seconds)
    duration = max(seconds, 4.0)

    records, problems = [], []

    act_samples: list[float] = []
    sequence: list[tuple[np.ndarray, ...]] = []

    class Recording(tracker_module.WholeBodyTracker):
        def act(self, reference, state):
            t0 = time.perf_counter()
            out = super().act(reference, state)
            act_samples.append(time.perf_counter() - t0)  # the recording below is not the controller's
            sol = self.diagnostics.solution
            assert sol is not None  # None only before the first solved QP
            records.append((self._q.copy(), self._v.copy(), sol.solve_time_s, self._prev_stance.copy(),
                            sol.iterations))
            qp = self.qp
            if len(records) % PROBLEM_STRIDE == 0:
                problems.append(tuple(m.copy() for m in (qp.H, qp.g, qp.A, qp.b, qp.C, qp.l, qp.u)))
            if len(sequence) < REPLAY_TICKS:
                sequence.append(tuple(m.copy() for m in (qp.H, qp.g, qp.A, qp.b, qp.C, qp.l, qp.u)))
            return out

    # build_loop makes the WBC tracker by its name in tracker_module: record through a subclass.
    with mock.patch.object(tracker_module, "WholeBodyTracker", Recording):
        walk, loop = velocity_walk(WALK_SPEED_MPS, duration, DEFAULT_TRACKER_HZ)
    tracker = loop.tracker
    qp_samples = [r[2] for r in records]

    # Baseline 1: RNEA + CRBA on the visited states.
    model = tracker.dyn.model
    data = model.createData()
    a0 = np.zeros(model.nv)
    dyn_samples = []
    for q, v, *_ in records:
        t0 = time.perf_counter()
        pin.rnea(model, data, q, v, a0)
        pin.crba(model, data, q)
        dyn_samples.append(time.perf_counter() - t0)

    # Baseline 2: the very same QPs (recorded every few ticks) solved cold by a fresh solver.
    from g1_control.ik.solver import import_proxsuite

    proxsuite = import_proxsuite()
    cold_samples = []
    for H, g, A, b, C, l, u in problems:
        t0 = time.perf_counter()
        cold = proxsuite.proxqp.dense.QP(H.shape[0], A.shape[0], C.shape[0])
        cold.settings.eps_abs = tracker.config.qp.eps_abs
        cold.settings.eps_rel = 0.0
        cold.settings.max_iter = tracker.config.qp.max_iter
        cold.init(H, g, A, b, C, l, u)
        cold.solve()
        cold_samples.append(time.perf_counter() - t0)

    replayed = replay_warm_starts(sequence, tracker.config.qp, tracker.qp.nv)
    sequence.clear()
    physics = physics_only_seconds(walk.sim_s, 0.002)
    qp50, qp99 = _pct(qp_samples)
    act50, act99 = _pct(act_samples)
    dyn50, dyn99 = _pct(dyn_samples)
    cold50, cold99 = _pct(cold_samples)
    rtf = walk.sim_s / walk.wall_s
    print(f"g1 bench wbc: {walk.sim_s:.1f} s simulated, velocity-commanded walk at {WALK_SPEED_MPS} m/s (the WBC's "
          f"own gait), WBC at {DEFAULT_TRACKER_HZ:.0f} Hz, physics 500 Hz, {len(records)} controller ticks")
    if walk.fall:
        print(f"  FELL: {walk.fall}")
    else:
        print(f"  no fall; ground truth over whole strides after 3 s: vx {walk.velocity_h[0]:.3f} m/s "
              f"(commanded {WALK_SPEED_MPS}), vy {walk.velocity_h[1]:+.3f} m/s, wz {walk.velocity_h[2]:+.3f} rad/s, "
              f"{walk.distance_m:.2f} m walked")
    print(f"  {'per tick':<34} {'p50 us':>8} {'p99 us':>8}")
    print(f"  {'QP solve (warm-started)':<34} {qp50:8.1f} {qp99:8.1f}   goal p99 <= 1000")
    print(f"  {'QP solve cold (baseline)':<34} {cold50:8.1f} {cold99:8.1f}   warm/cold p50 {qp50 / cold50:.2f}x"
          f" (the same {len(cold_samples)} problems, fresh solver each)")
    print(f"  {'pinocchio RNEA + CRBA (baseline)':<34} {dyn50:8.1f} {dyn99:8.1f}   QP/RNEA+CRBA p50 {qp50 / dyn50:.1f}x")
    print(f"  {'whole act()':<34} {act50:8.1f} {act99:8.1f}   act/RNEA+CRBA p50 {act50 / dyn50:.1f}x")
    print(f"  loop with WBC: {walk.wall_s:6.2f} s wall -> real-time factor {rtf:5.1f}x; physics alone "
          f"{physics:5.2f} s -> {walk.sim_s / physics:5.1f}x; loop/physics wall time {walk.wall_s / physics:.1f}x")
    iters = np.array([r[4] for r in records])
    print(f"  QP iterations p50/p99/max: {np.percentile(iters, 50):.0f}/{np.percentile(iters, 99):.0f}/{iters.max()} "
          f"(independent of machine load); ticks relaxed/unsolved: {tracker.diagnostics.solve_failures}/"
          f"{tracker.diagnostics.unsolved_ticks}; warm starts unsolved: {tracker.qp.warm_exits}, reset for a contact "
          f"change: {tracker.qp.contact_resets}, retried cold: {tracker.qp.cold_retries}")
    carry, reset = replayed["carried_over"], replayed["reset"]
    print(f"  warm starts, the walk's first {len(carry['solve_us'])} problems solved again in order (best of {REPLAY_ROUNDS}):")
    for name, r in (("carried over (the default)", carry), (f"reset to {RESET_MU_IN:g} on contact changes", reset)):
        p50, p99 = np.percentile(r["solve_us"], [50, 99])
        print(f"    {name:<38} solve p50 {p50:7.1f} us p99 {p99:7.1f} us, iterations p99 "
              f"{np.percentile(r['iterations'], 99):.0f} max {max(r['iterations'])}, warm starts unsolved "
              f"{r['warm_exits']}")
    ratio = np.percentile(reset["solve_us"], 99) / np.percentile(carry["solve_us"], 99)
    print(f"    reset/carried-over solve p99 {ratio:.2f}x")
    load1, _, _ = os.getloadavg()
    print(f"  1-minute load average during the run: {load1:.1f} on {os.cpu_count()} cores "
          "(p99 figures above 1 ms on a loaded machine are preemption, not solver work)")
    if args.json:
        Path(args.json).write_text(json.dumps({
            "simulated_s": walk.sim_s, "ticks": len(records), "fell": walk.fall is not None,
            "fall": str(walk.fall) if walk.fall else "", "speed_commanded_mps": WALK_SPEED_MPS,
            "velocity_true_h": walk.velocity_h.tolist(), "distance_m": walk.distance_m,
            "qp_p50_us": qp50, "qp_p99_us": qp99, "qp_cold_p50_us": cold50, "qp_cold_p99_us": cold99,
            "rnea_crba_p50_us": dyn50, "rnea_crba_p99_us": dyn99, "act_p50_us": act50, "act_p99_us": act99,
            "qp_iterations_p50": float(np.percentile(iters, 50)), "qp_iterations_p99": float(np.percentile(iters, 99)),
            "ticks_relaxed": tracker.diagnostics.solve_failures, "ticks_unsolved": tracker.diagnostics.unsolved_ticks,
            "qp_warm_exits": tracker.qp.warm_exits, "qp_contact_resets": tracker.qp.contact_resets,
            "qp_cold_retries": tracker.qp.cold_retries,
            "replay": {name: {"problems": len(r["solve_us"]), "warm_exits": r["warm_exits"],
                              "solve_p50_us": float(np.percentile(r["solve_us"], 50)),
                              "solve_p99_us": float(np.percentile(r["solve_us"], 99)),
                              "iterations_p99": float(np.percentile(r["iterations"], 99)),
                              "iterations_max": int(max(r["iterations"]))} for name, r in replayed.items()},
            "load_average_1min": load1, "loop_wall_s": walk.wall_s, "real_time_factor": rtf, "physics_only_wall_s": physics}, indent=2))
    return 1 if walk.fall else 0
