"""`g1 init DIR`: copy the shipped launch files somewhere to edit them."""

from __future__ import annotations

from pathlib import Path


def register(subparsers) -> None:
    parser = subparsers.add_parser(
        "init",
        help="copy the launch files into a folder to edit",
        description="Copy every launch file that comes with g1-control (g1 launch --list) into DIR, to edit "
        "and run with g1 launch DIR/NAME.yaml. Existing files are kept unless --force.",
    )
    parser.add_argument("dir", type=Path, help="folder to copy into (made if missing)")
    parser.add_argument("--force", action="store_true", help="overwrite files already there")
    parser.set_defaults(func=_run)


def _run(args) -> int:
    from g1_control.resources import copy_launch_files

    written = copy_launch_files(args.dir, force=args.force)
    print(f"{len(written)} launch files in {args.dir}:")
    for p in written:
        print(f"  {p}")
    first = next((p for p in written if p.stem == "sim_walk"), written[0] if written else None)
    if first is not None:
        print(f"edit one, then: g1 launch {first}")
    return 0
