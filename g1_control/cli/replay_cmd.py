"""`g1 replay RUN`: look at a recorded run again (viewer, headless MP4 or PNG, browser)."""

from __future__ import annotations

import argparse
import os
from pathlib import Path


def add_output_options(parser) -> None:
    """Where to show a playback (shared with g1 view)."""
    parser.add_argument("--video", nargs="?", const="", type=str, metavar="OUT.mp4",
                        help="write a headless MP4 with the overlay (default when no display exists)")
    parser.add_argument("--frame", type=float, metavar="SECONDS", help="write the frame at this time as a PNG")
    parser.add_argument("-o", "--out", type=Path, help="output file for --video/--frame")
    parser.add_argument("--web", nargs="?", const=8080, type=int, metavar="PORT",
                        help="play in the browser (viser) at http://127.0.0.1:PORT (default 8080), looping "
                        "until Ctrl-C")
    parser.add_argument("--speed", type=float, default=1.0, help="playback speed (viewer and browser)")
    parser.add_argument("--fps", type=float, default=25.0, help="video frame rate")
    parser.add_argument("--size", type=int, nargs=2, default=(640, 480), metavar=("W", "H"), help="video size")
    parser.add_argument("--once", action="store_true", help="browser: play once and exit instead of looping")


def show(pb, args, default_out: Path, stem: str) -> int:
    """Send playback `pb` where the options say: PNG, MP4, browser, or the MuJoCo viewer."""
    from g1_control.report import replay

    if args.frame is not None:
        out = args.out or default_out / f"{stem}-{args.frame:g}s.png"
        replay.write_frame(pb, args.frame, out, size=tuple(args.size))
        print(f"frame at {args.frame:g} s: {out}")
        return 0
    if args.web is not None:
        def ready(view):
            print(f"{pb.title}: open {view.url} in a browser (Ctrl-C stops)", flush=True)

        replay.serve_web(pb, port=args.web, speed=args.speed, repeat=not args.once, on_ready=ready)
        return 0
    if args.video is not None or not os.environ.get("DISPLAY"):
        out = args.out or (Path(args.video) if args.video else default_out / f"{stem}.mp4")
        if args.video is None:
            print("no display: writing a video instead of opening the viewer")
        backend = replay.write_video(pb, out, fps=args.fps, size=tuple(args.size))
        print(f"{pb.title}: {pb.duration_s:.1f} s -> {out} ({backend})")
        return 0
    replay.play_viewer(pb, speed=args.speed)
    return 0


def register(subparsers) -> None:
    parser = subparsers.add_parser(
        "replay",
        help="look at a recorded run again (viewer, video, browser)",
        description="Replay a run folder written by g1 launch (runs/NAME-TIME, or its log.npz) from its "
        "recorded base pose and joints and its scene (the tables, platforms and boxes of the launch.yaml in "
        "the folder, each box where truth.npz recorded it), with an overlay of the command, the achieved velocity "
        "(ground truth, 1 s gait-cycle mean) and the safety state: in the MuJoCo viewer when a display exists, "
        "else as a headless MP4 (RUN/replay.mp4); --frame writes one PNG; --web plays it in the browser.",
        epilog="examples:\n  g1 replay runs/sim_walk-20261121-154328\n  g1 replay runs/sim_walk-* --video\n"
        "  g1 replay RUN --frame 12.5          # RUN/replay-12.5s.png\n  g1 replay RUN --web 8080",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("run", type=Path, help="run folder (or its log.npz)")
    add_output_options(parser)
    parser.set_defaults(func=_run)


def _run(args) -> int:
    from g1_control.report.replay import from_run

    pb = from_run(args.run)
    folder = args.run if args.run.is_dir() else args.run.parent
    return show(pb, args, folder, "replay")
