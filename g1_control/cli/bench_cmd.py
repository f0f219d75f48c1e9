"""`g1 bench NAME`: speed benchmarks that print figures and ratios against a baseline
measured in the same run (never asserted in unit tests: the machines are shared and noisy)."""

from __future__ import annotations

import argparse
import importlib

from g1_control.errors import FanOutError
from g1_control.fanout import add_arguments as add_fanout_arguments

# name -> "module:function"; the function takes the parsed args and returns an exit code.
BENCHMARKS = {
    "loop": ("g1_control.tools.bench_loop:main", "full loop in lockstep: real-time factor, per-stage p50/p99"),
    "teleop": ("g1_control.tools.bench_teleop:main", "input event -> Command latency p50/p99 per device vs bare os.read"),
    "transport": ("g1_control.tools.bench_transport:main", "robot link: CRC, LowCmd/LowState encode/decode, safety filter (us/call)"),
    "ik": ("g1_control.tools.bench_ik:main", "IK retargeter: online solve p50/p99, offline frames/s per core"),
    "wbc": ("g1_control.tools.bench_wbc:main", "whole-body QP solve p50/p99 per tick vs RNEA+CRBA and cold solves; warm starts carried over vs reset on contact changes; loop real-time factor"),
    "generator": ("g1_control.tools.bench_generator:main",
                  "in-betweening L2P/L2Q/NPSS vs interpolation + motion matching; replan p50/p99; frames/s; 10-min rollout"),
    "execution": ("g1_control.tools.bench_execution:main",
                  "the repertoire in physics: one row per behaviour (success, falls, velocity/upper-body/hand/object "
                  "error, real-time factor); exits 1 on a fall"),
    "program": ("g1_control.tools.bench_program:main",
                "20 multi-step English instructions in physics: every step judged from ground truth (distance "
                "10 %, heading 10 deg), falls; --only 1,5 picks instructions"),
    "parser": ("g1_control.program.language.bench:bench_main",
               "instruction parser latency (30-word instructions): CPU and wall p50/p99, interleaved with a baseline"),
    "odometry": ("g1_control.tools.bench_odometry:main",
                 "world pose drift vs ground truth over 10 seeded random timelines: leg odometry (IMU + contact-aided "
                 "legs) vs velocity integration; cm per metre and per 90 deg (--seconds each, default 40)"),
    "locomotion": ("g1_control.tools.bench_locomotion:main",
                   "walking from ground truth: model-based WBC vs holosoma ppo and fastsac per axis and speed "
                   "(achieved vs commanded, off-axis, falls, act() CPU p50/p99 vs RNEA+CRBA); exits 1 on a fall"),
    "objects": ("g1_control.tools.bench_objects:main",
                "pick a box (floor/low/table/high support, 0.15-0.45 m, 0.2-6 kg, any yaw) and put it on another "
                "support, --trials drawn scenes judged from ground truth; a table per bucket, every refusal's reason; "
                "--tracker wbc: on the whole-body controller alone; --carry: 3-5 m between two tables on the "
                "whole-body controller's gait"),
    "bottle": ("g1_control.tools.bench_bottle:main",
               "a bottle picked with one Dex3 hand (force-limited grasp) and put down upright, --trials drawn scenes "
               "(table height, bottle size/mass/friction, hand, place) judged from ground truth; peak finger squeeze "
               "against its limit; --carry: put down on a second table, walked to holding it; exits 1 on a fall"),
    "robust": ("g1_control.tools.bench_robust:main",
               "wbc vs ppo walking 0.6 m/s and the step (sim_step) on --draws seeded randomised robots (link mass, "
               "CoM, motor strength, latency, foot friction): falls, achieved vs commanded from ground truth; exits 1 "
               "on a fall"),
    "stairs": ("g1_control.tools.bench_stairs:main",
               "WBC walking into stairs (3 x 0.15 m up, landing, down) and a 0.20 m platform found in the scene, seeded "
               "approach angles/offsets: top reached, across, falls (ground truth); --seed first seed, --trials count, "
               "--only stairs|platform|step; exits 1 on a fall"),
    "stall": ("g1_control.tools.bench_stall:main",
              "the host stalls the WBC's loop 40-200 ms at --trials seeded instants of a walk (29- and 23-DoF): the "
              "last command resent as it is vs its hold form after its life (safety.command_hold_ticks); falls, trips, "
              "peak joint speed (ground truth)"),
    "envelope": ("g1_control.tools.bench_envelope:main",
                 "the walking tracker's achievable velocity per axis and style; --write ships it as the command limits"),
}

FANS_OUT = ("bottle", "execution", "objects", "program")
"""The benchmarks whose trials fan out over --jobs processes or a --ray cluster (g1_control/fanout.py):
their per-trial work is a function of the trial's task alone, so the figures do not depend on where it ran."""


def register(subparsers) -> None:
    parser = subparsers.add_parser(
        "bench",
        help="run a speed benchmark",
        description="Speed benchmarks. Each prints its figures and ratios against a baseline measured in the same run.\n"
        + "\n".join(f"  {name:10s} {text}" for name, (_, text) in BENCHMARKS.items()),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("name", choices=sorted(BENCHMARKS), help="which benchmark")
    parser.add_argument("--seconds", type=float, default=20.0, help="simulated/measured duration (default 20)")
    parser.add_argument("--json", metavar="FILE", help="also write the figures as JSON")
    parser.add_argument("--only", metavar="PREFIXES", help="execution/envelope/locomotion: only rows (styles, controller/case) starting with these "
                        "comma-separated prefixes; program: instruction numbers (1,5); stall: g1_29dof or g1_23dof")
    parser.add_argument("--seed", type=int, default=0, help="execution: the suite's seed (push timing; default 0); "
                        "robust: the first draw's seed; stairs: the first seed of the draws; objects, bottle: the scenes' seed; "
                        "stall: the instants' seed")
    parser.add_argument("--draws", type=int, default=10, help="robust: how many seeded randomised robots (default 10)")
    parser.add_argument("--trials", type=int, default=None,
                        help="stairs: seeded draws per course (default 5); objects, bottle: drawn scenes (default 10); stall: "
                        "instants per stall length (default 8)")
    parser.add_argument("--video", metavar="DIR", help="execution: a video per behaviour into DIR")
    parser.add_argument("--trace", metavar="DIR", help="stairs: a CSV per trial into DIR (every 0.02 s: soles, "
                        "swing reference, DCM, CoP, CoM height, fastest joint)")
    parser.add_argument("--write", action="store_true", help="envelope: write the measured envelope next to the "
                        "policy spec (the loop builder's command limits)")
    parser.add_argument("--carry", action="store_true", help="bottle: put the bottle down on a second table "
                        "1.0-1.8 m from the start, off to the side of the first (walked to holding it); objects: "
                        "carry the box 3-5 m between two 0.60-0.85 m tables (0.20-0.35 m, 1-4 kg) on the "
                        "whole-body controller, its own gait walking it")
    parser.add_argument("--tracker", choices=("layer", "wbc"), default=None,
                        help="objects: the scenes' tracker: layer (the default: the walking policy walks, the "
                        "whole-body controller picks and places, a carry is whole-body steps) or wbc (the whole-body "
                        "controller alone at 250 Hz, its own gait walking a held box; --carry always)")
    add_fanout_arguments(parser, what="/".join(FANS_OUT) + " trials")
    parser.set_defaults(func=_run)


def _run(args) -> int:
    if args.name not in FANS_OUT and (args.ray is not None or args.jobs != 1):
        raise FanOutError(f"--jobs/--ray: {args.name} runs in this process; they apply to {', '.join(FANS_OUT)}")
    module_name, func_name = BENCHMARKS[args.name][0].split(":")
    return int(getattr(importlib.import_module(module_name), func_name)(args) or 0)
