"""`g1 launch FILE`: validate a launch file and run it."""

from __future__ import annotations

import argparse
import os
from pathlib import Path

EXIT_OK, EXIT_FAILED, EXIT_TRIPPED = 0, 1, 3
"""g1 launch's exit status: the run as planned; a fall, a goal not reached (or an error before the run);
the safety layer tripped (damping) and the robot did not fall. A signal N ends it with 128 + N."""

EXIT_STATUS = ("exit status:\n"
               "  0  the run completed: no fall, no safety trip, every goal reached\n"
               "  1  the robot fell (whatever tripped before), a goal was not reached, or an error\n"
               "     (e.g. an invalid launch file)\n"
               "  3  the safety layer tripped (damping) and the robot did not fall (summary.json's\n"
               "     status \"fault\", end_reason naming the trip)\n"
               "  128 + N  a signal N ended the run (130 SIGINT, 143 SIGTERM)")


def exit_status(result) -> int:
    """EXIT_FAILED on a fall (whatever tripped before it), else EXIT_TRIPPED on an unplanned safety trip
    (found by its type, as the run folder's "fault" status is), else EXIT_FAILED when a goal was not
    reached, else EXIT_OK."""
    from g1_control.loop.control_loop import first_fault

    if result.fell:
        return EXIT_FAILED
    if first_fault(result.events) is not None:
        return EXIT_TRIPPED
    missed = [g for g in result.extra.get("goals", []) if g["status"] != "reached"]
    return EXIT_FAILED if missed else EXIT_OK


def register(subparsers) -> None:
    parser = subparsers.add_parser(
        "launch",
        help="validate and run a launch file (sim)",
        description="Validate a launch file, then run it: progress while it runs, a summary at the end "
        "(fall, commanded vs achieved velocity per segment, stage timings, real-time factor), and a run "
        "folder with log.npz, velocity.png and, where headless rendering works, video.mp4 (with an overlay "
        "of command, achieved velocity and safety state). FILE is a path or the name of a launch file "
        "that comes with g1-control (g1 launch --list; g1 init DIR copies them for editing).",
        epilog=EXIT_STATUS + "\n\nexamples:\n  g1 launch sim_walk\n  g1 launch launch/sim_walk.yaml --check\n"
        "  g1 launch sim_random --seed 3 --no-video\n"
        "  g1 launch sim_walk --set tracker.policy=holosoma_loco_fastsac --set output.video_fps=20\n"
        "  g1 launch sim_walk --web        # watch it in the browser (http://127.0.0.1:8080)\n"
        "then: g1 replay runs/sim_walk-*   # look at the run again",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("file", nargs="?", help="launch file (YAML path) or a shipped launch file's name")
    parser.add_argument("--list", action="store_true", help="list the launch files that come with g1-control")
    parser.add_argument("--check", action="store_true", help="validate the file (and its policy) and exit")
    parser.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE",
                        help="override any launch-file key, dotted (tracker.policy=holosoma_loco_fastsac, "
                        "safety.max_tilt_rad=0.8, input.timeline[1].vx_mps=0.3); VALUE is YAML; validated by "
                        "the same schema; repeatable")
    parser.add_argument("--out", type=Path, help="run folder root (default: the file's output.dir)")
    parser.add_argument("--seed", type=int, help="seed for a random command timeline (input.type: random)")
    parser.add_argument("--duration", type=float, help="override the run length in seconds")
    video = parser.add_mutually_exclusive_group()
    video.add_argument("--video", dest="video", action="store_true", default=None, help="render video.mp4")
    video.add_argument("--no-video", dest="video", action="store_false", help="skip the video")
    parser.add_argument("--viewer", choices=("auto", "on", "off"), help="MuJoCo viewer (default: the file's "
                        "viewer setting; auto opens it when a display exists)")
    parser.add_argument("--web", nargs="?", const=8080, type=int, metavar="PORT",
                        help="show the robot live in the browser (viser) at http://127.0.0.1:PORT (default 8080); "
                        "runs on the wall clock")
    parser.add_argument("--quiet", action="store_true", help="no progress bar")
    parser.set_defaults(func=_run)


def _list() -> int:
    import yaml

    from g1_control.resources import launch_dir, launch_files

    print(f"launch files in {launch_dir()}:")
    for name, path in launch_files().items():
        try:
            about = (yaml.safe_load(path.read_text()) or {}).get("description", "")
        except yaml.YAMLError:
            about = "(not valid YAML)"
        print(f"  {name:20s} {' '.join(str(about).split())[:100]}")
    print("run one with `g1 launch NAME`; copy them for editing with `g1 init DIR`")
    return 0


def _run(args) -> int:
    if args.list:
        return _list()
    if not args.file:
        from g1_control.errors import LaunchFileError

        raise LaunchFileError("name a launch file (a path or a name from g1 launch --list), e.g. g1 launch sim_walk")
    from g1_control.launch.schema import load_launch
    from g1_control.resources import resolve_launch

    path, shipped = resolve_launch(args.file)
    if shipped and not args.quiet:
        print(f"launch file: {path}")
    launch = load_launch(path, overrides=args.overrides)
    if args.seed is not None:
        launch.input.random.seed = args.seed
    if args.duration is not None:
        launch.duration_s = args.duration
    if args.check:
        from g1_control.launch.variant import POLICY_TRACKERS, check_tracker_fits

        if launch.tracker.type in POLICY_TRACKERS:
            from g1_control.trackers.policy_spec import load_spec

            spec = load_spec(launch.tracker.policy)
            check_tracker_fits(launch, spec)
            what = f"policy {spec.name}"
        else:
            check_tracker_fits(launch)
            what = f"tracker {launch.tracker.type}"
        randomized = (f", randomised (seed {launch.backend.randomize.seed})" if launch.backend.randomize is not None
                      else "")
        print(f"{args.file}: OK ({launch.name}: {launch.backend.type} {launch.backend.mode}{randomized}, "
              f"{launch.backend.expected_variant}, {what}, {launch.total_duration_s:.1f} s, input {launch.input.type})")
        return 0
    from g1_control.launch.runner import run
    from g1_control.report.results import format_summary

    setting = {"on": True, "off": False, "auto": "auto"}[args.viewer] if args.viewer else launch.viewer
    viewer = setting is True or (setting == "auto" and bool(os.environ.get("DISPLAY")))
    if viewer or args.web is not None:
        launch.backend.mode = "wallclock"
    result = run(launch, out_root=args.out or Path(launch.output.dir), video=args.video,
                 progress=not args.quiet, viewer=viewer, web_port=args.web)
    print(format_summary(result))
    if result.run_dir is not None:
        print(f"look again: g1 replay {result.run_dir}")
    return exit_status(result)
