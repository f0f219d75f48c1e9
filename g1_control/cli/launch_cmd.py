"""`g1 launch FILE`: validate a launch file and run it."""

from __future__ import annotations

import argparse
import os
from pathlib import Path


def register(subparsers) -> None:
    parser = subparsers.add_parser(
        "launch",
        help="validate and run a launch file (sim)",
        description="Validate a launch file, then run it: progress while it runs, a summary at the end "
        "(fall, commanded vs achieved velocity per segment, stage timings, real-time factor), and a run "
        "folder with log.npz, velocity.png and, where headless rendering works, video.mp4.",
        epilog="examples:\n  g1 launch launch/sim_walk.yaml\n  g1 launch launch/sim_walk.yaml --check\n"
        "  g1 launch launch/sim_random.yaml --seed 3 --no-video",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("file", type=Path, help="launch file (YAML)")
    parser.add_argument("--check", action="store_true", help="validate the file (and its policy) and exit")
    parser.add_argument("--out", type=Path, help="run folder root (default: the file's output.dir)")
    parser.add_argument("--seed", type=int, help="seed for a random command timeline (input.type: random)")
    parser.add_argument("--duration", type=float, help="override the run length in seconds")
    video = parser.add_mutually_exclusive_group()
    video.add_argument("--video", dest="video", action="store_true", default=None, help="render video.mp4")
    video.add_argument("--no-video", dest="video", action="store_false", help="skip the video")
    parser.add_argument("--viewer", choices=("auto", "on", "off"), help="MuJoCo viewer (default: the file's "
                        "viewer setting; auto opens it when a display exists)")
    parser.add_argument("--quiet", action="store_true", help="no progress bar")
    parser.set_defaults(func=_run)


def _run(args) -> int:
    from g1_control.launch.schema import load_launch

    launch = load_launch(args.file)
    if args.seed is not None:
        launch.input.random.seed = args.seed
    if args.duration is not None:
        launch.duration_s = args.duration
    if args.check:
        from g1_control.trackers.policy_spec import load_spec

        spec = load_spec(launch.tracker.policy)
        print(f"{args.file}: OK ({launch.name}: {launch.backend.type} {launch.backend.mode}, "
              f"policy {spec.name}, {launch.total_duration_s:.1f} s, input {launch.input.type})")
        return 0
    from g1_control.launch.runner import format_summary, run

    setting = {"on": True, "off": False, "auto": "auto"}[args.viewer] if args.viewer else launch.viewer
    viewer = setting is True or (setting == "auto" and bool(os.environ.get("DISPLAY")))
    if viewer:
        launch.backend.mode = "wallclock"
    result = run(launch, out_root=args.out or Path(launch.output.dir), video=args.video,
                 progress=not args.quiet, viewer=viewer)
    print(format_summary(result))
    return 1 if result.fell else 0
