"""`g1 bench loop`: the full loop in lockstep against its own physics, measured in the same run.

Figures: real-time factor of the whole loop (goal >= 20x), per-stage p50/p99, and the ratio of the
loop's wall time to a baseline that steps the same MuJoCo scene through the same simulated time
replaying the loop's own motor commands (what the loop costs on top of the physics it drives): each
slice, a second backend starts from a copy of the loop's MjData and is handed the very commands the
loop wrote, tick for tick, through the same motor law; its final state is checked to be the loop's.
The earlier baseline, the unpowered robot lying on the floor (bare mj_step: a different, costlier
contact state than a walking robot's), is still measured and printed, for comparison.

The loop and the baselines run interleaved, one simulated second of each in turn, so that all
meet the same load on a shared machine; the ratio is also given in CPU (process) time, which
other processes disturb far less than wall time, and per slice (its spread shows the noise).
"""

from __future__ import annotations

import json
import time
from pathlib import Path

import numpy as np

from g1_control.launch.schema import LaunchFile, Segment

SLICE_S = 1.0
"""Simulated seconds of the loop, then of each baseline, in turn."""


def bench_launch(seconds: float) -> LaunchFile:
    launch = LaunchFile(name="bench_loop")
    step = seconds / 4
    launch.input.timeline = [Segment(step, label="stand"), Segment(step, vx_mps=0.5, label="forward"),
                             Segment(step, wz_radps=0.5, label="turn"), Segment(step, label="stand")]
    launch.output.video = False
    return launch


def bare_physics(physics_dt_s: float):
    """(model, data) of the scene with the robot standing and unpowered: bare mj_step."""
    from g1_control.sim.mujoco_backend import MujocoBackend, MujocoConfig
    from g1_control.types import MotorCommand

    backend = MujocoBackend(MujocoConfig(physics_dt_s=physics_dt_s))
    backend.reset()
    backend.write_command(MotorCommand())  # no motor law at all: bare physics (the unpowered robot falls)
    return backend.model, backend.data


def physics_only_seconds(seconds: float, physics_dt_s: float) -> float:
    import mujoco

    model, data = bare_physics(physics_dt_s)
    n = round(seconds / physics_dt_s)
    t0 = time.perf_counter()
    for _ in range(n):
        mujoco.mj_step(model, data)
    return time.perf_counter() - t0


class CommandRecorder:
    """Records what the loop hands its lockstep backend: (command, dt_s, ticks) per step_ticks call,
    in order (the command objects themselves: the loop never changes one it has handed on)."""

    def __init__(self, backend):
        self.calls: list[tuple] = []
        self._step_ticks = backend.step_ticks
        backend.step_ticks = self  # the loop looks the method up on every call

    def __call__(self, command, dt_s: float, n: int) -> None:
        self.calls.append((command, dt_s, n))
        self._step_ticks(command, dt_s, n)

    def take(self) -> list[tuple]:
        calls, self.calls = self.calls, []
        return calls


def main(args) -> int:
    import mujoco

    from g1_control.launch.builder import build_loop, make_sim_backend

    seconds = float(args.seconds)
    launch = bench_launch(seconds)
    sim = make_sim_backend(launch)
    loop = build_loop(launch, backend=sim)
    loop.reset()
    recorder = CommandRecorder(sim)
    replay = make_sim_backend(launch)
    replay.reset()
    model, data = bare_physics(launch.backend.physics_dt_s)
    ticks_total = round(seconds * launch.rates.lowlevel_hz)
    ticks_per_slice = max(1, round(SLICE_S * launch.rates.lowlevel_hz))
    steps_per_tick = round(1.0 / (launch.rates.lowlevel_hz * launch.backend.physics_dt_s))
    slices = []  # (loop, replay, unpowered) wall, then the same in CPU time, per slice
    replay_error = 0.0
    done = 0
    try:
        while done < ticks_total:
            n = min(ticks_per_slice, ticks_total - done)
            mujoco.mj_copyData(replay.data, replay.model, sim.data)  # the replay starts where the loop does
            w0, c0 = time.perf_counter(), time.process_time()
            loop.scheduler.run(n)
            w1, c1 = time.perf_counter(), time.process_time()
            for command, dt_s, ticks in recorder.take():
                replay.step_ticks(command, dt_s, ticks)
            w2, c2 = time.perf_counter(), time.process_time()
            for _ in range(n * steps_per_tick):
                mujoco.mj_step(model, data)
            w3, c3 = time.perf_counter(), time.process_time()
            replay_error = max(replay_error, float(np.max(np.abs(replay.data.qpos - sim.data.qpos))))
            slices.append((w1 - w0, w2 - w1, w3 - w2, c1 - c0, c2 - c1, c3 - c2))
            done += n
    finally:
        loop.input.close()
        loop.backend.close()
    loop_wall, base_wall, floor_wall, loop_cpu, base_cpu, floor_cpu = np.sum(slices, axis=0)
    per_slice = np.array([s[0] / s[1] for s in slices])
    rtf = seconds / loop_wall
    timings = loop.scheduler.report()
    print(f"g1 bench loop: {seconds:.0f} s simulated, physics {1 / launch.backend.physics_dt_s:.0f} Hz, "
          f"low-level {launch.rates.lowlevel_hz:.0f} Hz, tracker {launch.rates.tracker_hz:.0f} Hz; "
          f"loop and baselines interleaved in {SLICE_S:.0f} s slices")
    print(f"  full loop:     {loop_wall:7.2f} s wall  -> real-time factor {rtf:6.1f}x  (goal >= 20x)"
          f"{'  FELL: ' + str(loop.fall) if loop.fell else ''}")
    print(f"  its physics:   {base_wall:7.2f} s wall  -> real-time factor {seconds / base_wall:6.1f}x  (baseline: "
          f"the loop's own motor commands replayed; max |qpos - loop's| {replay_error:.1e})")
    print(f"  loop / its physics wall time:  {loop_wall / base_wall:.2f}x   (per slice: median "
          f"{np.median(per_slice):.2f}x, range {per_slice.min():.2f}-{per_slice.max():.2f}x)")
    print(f"  loop / its physics CPU time:   {loop_cpu / base_cpu:.2f}x   ({loop_cpu:.2f} s / {base_cpu:.2f} s)")
    print(f"  (earlier baseline, the unpowered robot on the floor: {floor_wall:.2f} s wall, loop / it "
          f"{loop_wall / floor_wall:.2f}x wall, {loop_cpu / floor_cpu:.2f}x CPU)")
    print(f"\n  {'stage':<12} {'calls':>7} {'p50 us':>8} {'p99 us':>8} {'mean us':>8}")
    for name, t in timings.items():
        print(f"  {name:<12} {t['calls']:>7} {t['p50_us']:>8.1f} {t['p99_us']:>8.1f} {t['mean_us']:>8.1f}")
    if args.json:
        Path(args.json).write_text(json.dumps({
            "seconds": seconds, "loop_wall_s": loop_wall, "real_time_factor": rtf,
            "physics_only_wall_s": base_wall, "ratio_loop_to_physics": loop_wall / base_wall,
            "ratio_per_slice": per_slice.tolist(), "loop_cpu_s": loop_cpu, "physics_only_cpu_s": base_cpu,
            "ratio_loop_to_physics_cpu": loop_cpu / base_cpu, "replay_max_qpos_error": replay_error,
            "unpowered_floor_wall_s": floor_wall, "unpowered_floor_cpu_s": floor_cpu,
            "ratio_loop_to_unpowered_floor": loop_wall / floor_wall, "stages": timings, "fell": loop.fell,
            "fall": str(loop.fall) if loop.fall else None}, indent=2))
    return 1 if loop.fell else 0
