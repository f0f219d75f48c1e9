"""`g1 bench loop`: the full loop in lockstep against bare physics, measured in the same run.

Figures: real-time factor of the whole loop (goal >= 20x), per-stage p50/p99, and the ratio of
the loop's wall time to a baseline that only steps the same MuJoCo model for the same simulated
time (what the loop costs on top of physics).
"""

from __future__ import annotations

import json
import time
from pathlib import Path

from g1_control.launch.schema import LaunchFile, Segment


def bench_launch(seconds: float) -> LaunchFile:
    launch = LaunchFile(name="bench_loop")
    step = seconds / 4
    launch.input.timeline = [Segment(step, label="stand"), Segment(step, vx_mps=0.5, label="forward"),
                             Segment(step, wz_radps=0.5, label="turn"), Segment(step, label="stand")]
    launch.output.video = "off"
    return launch


def physics_only_seconds(seconds: float, physics_dt_s: float) -> float:
    import mujoco

    from g1_control.sim.mujoco_backend import MujocoBackend, MujocoConfig
    from g1_control.types import MotorCommand

    backend = MujocoBackend(MujocoConfig(physics_dt_s=physics_dt_s))
    backend.reset()
    backend.write_command(MotorCommand())  # no motor law at all: bare physics (the unpowered robot falls)
    model, data = backend.model, backend.data
    n = round(seconds / physics_dt_s)
    t0 = time.perf_counter()
    for _ in range(n):
        mujoco.mj_step(model, data)
    return time.perf_counter() - t0


def main(args) -> int:
    from g1_control.launch.runner import run

    seconds = float(args.seconds)
    launch = bench_launch(seconds)
    result = run(launch, progress=False)
    baseline = physics_only_seconds(seconds, launch.backend.physics_dt_s)
    rtf = result.real_time_factor
    print(f"g1 bench loop: {seconds:.0f} s simulated, physics {1 / launch.backend.physics_dt_s:.0f} Hz, "
          f"low-level {launch.rates.lowlevel_hz:.0f} Hz, tracker {launch.rates.tracker_hz:.0f} Hz")
    print(f"  full loop:     {result.wall_s:7.2f} s wall  -> real-time factor {rtf:6.1f}x  (goal >= 20x)"
          f"{'  FELL' if result.fell else ''}")
    print(f"  physics only:  {baseline:7.2f} s wall  -> real-time factor {seconds / baseline:6.1f}x  (baseline)")
    print(f"  loop / physics-only wall time: {result.wall_s / baseline:.2f}x")
    print(f"\n  {'stage':<12} {'calls':>7} {'p50 us':>8} {'p99 us':>8} {'mean us':>8}")
    for name, t in result.timings.items():
        print(f"  {name:<12} {t['calls']:>7} {t['p50_us']:>8.1f} {t['p99_us']:>8.1f} {t['mean_us']:>8.1f}")
    if args.json:
        Path(args.json).write_text(json.dumps({
            "seconds": seconds, "loop_wall_s": result.wall_s, "real_time_factor": rtf,
            "physics_only_wall_s": baseline, "ratio_loop_to_physics": result.wall_s / baseline,
            "stages": result.timings, "fell": result.fell}, indent=2))
    return 0
