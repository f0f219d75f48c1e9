"""`g1 bench envelope`: what the walking tracker delivers, per axis and per style, measured in
physics; `--write` ships it next to the policy spec, where the loop builder's command limits come
from (Tracker.command_limits), so a full stick asks only for what the robot does.

For each style and direction (+vx, -vx, +vy, -vy, +wz, -wz) the commands of a ladder are tried
from a value known to work upward until one misses: achieved (steady state, gait-cycle mean,
ground truth) within 15 % of the command, off-axis speed within 0.075, upper body within 0.1 rad
RMS of the plan, no fall. The envelope of a direction is the last command that met all of it
(if the ladder's first value misses, lower values are tried). The shipped limits hold for every
style. The pelvis height range: the lowest planned height the tracker walks at 0.3 m/s within
1 cm (and within 15 % of the speed). The policy runs on its trained command range here (tracker.envelope_limits false), so the
measurement is not clipped by an earlier envelope.

    g1 bench envelope                      # measure and print (~25 min simulated for 8 styles)
    g1 bench envelope --only default,carry
    g1 bench envelope --write              # ship it: g1_control/policies/specs/<policy>.envelope.json
"""

from __future__ import annotations

import json
import time
from pathlib import Path

from g1_control.generator.styles import ROLLOUT_STYLES
from g1_control.tools.bench_execution import SPEED_TOLERANCE_PCT, judge_walk
from g1_control.tools.physics_trials import Trial, run_trial, walk_timeline
from g1_control.trackers.envelope import Envelope, envelope_path
from g1_control.trackers.policy_spec import load_spec
from g1_control.types import CommandLimits

POLICY = "holosoma_loco_ppo"
LADDERS: dict[str, tuple[int, tuple[float, ...]]] = {
    "vx_mps": (0, (0.5, 0.55, 0.6, 0.65, 0.7, 0.8, 0.9, 1.0)),
    "-vx_mps": (0, (-0.3, -0.35, -0.4, -0.45, -0.5, -0.6, -0.8, -1.0)),
    "vy_mps": (1, (0.2, 0.25, 0.3, 0.35, 0.4, 0.5)),
    "-vy_mps": (1, (-0.2, -0.25, -0.3, -0.35, -0.4, -0.5)),
    "wz_radps": (2, (0.5, 0.6, 0.7, 0.8, 0.9, 1.0)),
    "-wz_radps": (2, (-0.5, -0.6, -0.7, -0.8, -0.9, -1.0)),
}
"""direction -> (axis, commands tried in order)."""
BELOW = {0: (0.4, 0.3, 0.2), 1: (0.15, 0.1), 2: (0.4, 0.3, 0.2)}
"""Magnitudes tried when a ladder's first command already misses."""
HEIGHTS_M = (0.70, 0.67, 0.65, 0.63, 0.61)
HEIGHT_SPEED_MPS = 0.3
HEIGHT_TOLERANCE_M = 0.01


def probe(style: str, axis: int, value: float, log: list) -> bool:
    command = [0.0, 0.0, 0.0]
    command[axis] = value
    command_t = (command[0], command[1], command[2])
    result = run_trial(Trial(f"envelope {style} {value:+.2f}@{axis}", walk_timeline(style, command_t),
                             policy=POLICY, envelope_limits=False))
    verdict = judge_walk(command_t)(result)
    figures = verdict.values
    log.append({"style": style, "command": command, "met": verdict.ok, "error_pct": figures.get("velocity_error_pct"),
                "drift": figures.get("drift"), "upper_body_rms_rad": figures.get("upper_body_rms_rad"),
                "note": verdict.text})
    print(f"  {style:<12} {['vx', 'vy', 'wz'][axis]} {value:+.2f}: {'ok  ' if verdict.ok else 'miss'} "
          f"{verdict.text}", flush=True)
    return verdict.ok


def direction_limit(style: str, axis: int, ladder: tuple[float, ...], log: list) -> float:
    best = 0.0
    for value in ladder:
        if not probe(style, axis, value, log):
            break
        best = value
    if best == 0.0:
        sign = 1.0 if ladder[0] > 0 else -1.0
        for magnitude in BELOW[axis]:
            if probe(style, axis, sign * magnitude, log):
                return sign * magnitude
    return best


def height_limit(log: list) -> float:
    """The lowest planned pelvis height walked at 0.3 m/s within 1 cm (default style)."""
    lowest = None
    for height in HEIGHTS_M:
        command = (HEIGHT_SPEED_MPS, 0.0, 0.0)
        result = run_trial(Trial(f"envelope height {height}", walk_timeline("default", command, pelvis_height_m=height),
                                 policy=POLICY, envelope_limits=False))
        verdict = judge_walk(command, height, HEIGHT_TOLERANCE_M)(result)
        log.append({"style": "default", "pelvis_height_m": height, "met": verdict.ok, "note": verdict.text})
        print(f"  pelvis {height:.2f} m at vx {HEIGHT_SPEED_MPS}: {'ok  ' if verdict.ok else 'miss'} {verdict.text}",
              flush=True)
        if not verdict.ok:
            break
        lowest = height
    return lowest if lowest is not None else CommandLimits().pelvis_height_m[1]


def main(args) -> int:
    only = getattr(args, "only", None)
    styles = [s for s in ROLLOUT_STYLES if not only or any(s.startswith(p) for p in only.split(","))]
    t0 = time.perf_counter()
    log: list[dict] = []
    per_style: dict[str, dict[str, tuple[float, float]]] = {}
    print(f"g1 bench envelope: {POLICY}, styles {', '.join(styles)}; within {SPEED_TOLERANCE_PCT:.0f} % "
          "(gait-cycle mean, ground truth), no fall")
    for style in styles:
        limits = {name: direction_limit(style, axis, ladder, log) for name, (axis, ladder) in LADDERS.items()}
        per_style[style] = {axis: (limits["-" + axis], limits[axis]) for axis in ("vx_mps", "vy_mps", "wz_radps")}
        print(f"{style}: " + ", ".join(f"{k} [{lo:+.2f}, {hi:+.2f}]" for k, (lo, hi) in per_style[style].items()),
              flush=True)
    lowest = height_limit(log)
    envelope = Envelope(
        **{axis: (max(r[axis][0] for r in per_style.values()), min(r[axis][1] for r in per_style.values()))
           for axis in ("vx_mps", "vy_mps", "wz_radps")},
        pelvis_height_m=(lowest, CommandLimits().pelvis_height_m[1]), tolerance_pct=SPEED_TOLERANCE_PCT,
        per_style=per_style,
        measured_with=f"g1 bench envelope{' --only ' + only if only else ''} (LocomotionPolicyTracker, velocity "
                      f"correction on; {time.strftime('%Y-%m-%d')})")
    print(f"\nenvelope (every style): vx {envelope.vx_mps}, vy {envelope.vy_mps}, wz {envelope.wz_radps}, pelvis height "
          f"{envelope.pelvis_height_m} m; trained range {load_spec(POLICY).command_ranges}; "
          f"{time.perf_counter() - t0:.0f} s wall")
    if args.write:
        spec_file = load_spec(POLICY).spec_file
        assert spec_file is not None  # load_spec always records it
        path = envelope_path(spec_file)
        envelope.write(path)
        print(f"wrote {path}")
    if args.json:
        Path(args.json).write_text(json.dumps({"envelope": envelope.__dict__, "probes": log}, indent=1, default=list))
    return 0
