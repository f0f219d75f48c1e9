"""`g1 view CLIP`: look at any G1 motion clip (viewer, headless MP4 or PNG, browser)."""

from __future__ import annotations

import argparse
from pathlib import Path

from g1_control.cli.replay_cmd import add_output_options, show


def register(subparsers) -> None:
    parser = subparsers.add_parser(
        "view",
        help="look at a motion clip (viewer, video, browser)",
        description="Play a G1 motion clip: the motion library's npz (g1 library build), a retargeted clip "
        "(g1 retarget), a BeyondMimic/mjlab npz or a Unitree CSV; a run's log.npz plays as g1 replay. The "
        "overlay shows the clip's name, frame, style and foot contacts; the clip's scene shapes (climbing "
        "boxes) and the object it handles (moving as the clip says) are drawn with the robot. Viewer with a display, else a headless "
        "MP4 next to the clip (CLIP.mp4); --frame writes one PNG; --web plays it in the browser.",
        epilog="examples:\n  g1 view out/walk.npz\n  g1 view dance.csv --video dance.mp4\n"
        "  g1 view out/walk.npz --frame 1.0 -o walk.png\n  g1 view out/walk.npz --web",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("clip", type=Path, help="motion clip (.npz or .csv)")
    add_output_options(parser)
    parser.set_defaults(func=_run)


def _run(args) -> int:
    from g1_control.report.replay import from_clip

    pb = from_clip(args.clip)
    return show(pb, args, args.clip.parent, args.clip.stem)
