"""`g1`: one command, one subcommand per job.

Each subcommand lives in its own module under g1_control.cli and exposes
`register(subparsers)`, which adds its parser and sets `func` (called with the parsed args,
returning an exit code). Modules are imported only when listed here, and heavy imports happen
inside `func`, so `g1 --help` stays fast.
"""

from __future__ import annotations

import argparse
import importlib
import sys
from pathlib import Path

from g1_control.errors import G1ControlError

SUBCOMMAND_MODULES = (
    "g1_control.cli.launch_cmd",
    "g1_control.cli.say_cmd",
    "g1_control.cli.replay_cmd",
    "g1_control.cli.view_cmd",
    "g1_control.cli.init_cmd",
    "g1_control.cli.docs_cmd",
    "g1_control.cli.policies_cmd",
    "g1_control.cli.bench_cmd",
    "g1_control.cli.input_cmd",
    "g1_control.cli.sim_robot_cmd",
    "g1_control.cli.hands_cmd",
    "g1_control.cli.retarget_cmd",
    "g1_control.cli.check_cmd",
    "g1_control.cli.deploy_cmd",
    "g1_control.cli.doctor_cmd",
    "g1_control.cli.library_cmd",
    "g1_control.cli.train_cmd",
    "g1_control.cli.soak_cmd",
)


def version() -> str:
    from importlib.metadata import PackageNotFoundError
    from importlib.metadata import version as dist_version

    import g1_control

    try:
        installed = dist_version("g1-control")
    except PackageNotFoundError:
        installed = None
    where = Path(g1_control.__file__).resolve().parent
    return f"g1-control {installed or g1_control.__version__} ({where})"


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="g1",
        description="g1-control: real-time whole-body control for the Unitree G1, in simulation and on the robot.",
        epilog="Start with: g1 launch sim_walk   (g1 launch --list: the launch files; g1 init DIR: copies to edit;\n"
        "g1 docs: the README, architecture, API and package docs; every command has --help)",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("--version", action="version", version=version())
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND")
    for module_name in SUBCOMMAND_MODULES:
        importlib.import_module(module_name).register(subparsers)
    return parser


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if not getattr(args, "func", None):
        parser.print_help()
        return 2
    try:
        return int(args.func(args) or 0)
    except G1ControlError as exc:
        print(f"g1 {args.command}: error: {exc}", file=sys.stderr)
        return 1
    except KeyboardInterrupt as exc:
        signum = getattr(exc, "signum", 2)
        print(f"g1 {args.command}: interrupted ({exc or 'SIGINT received'})", file=sys.stderr)
        return 128 + signum


if __name__ == "__main__":
    sys.exit(main())
