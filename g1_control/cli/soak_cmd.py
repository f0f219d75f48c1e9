"""`g1 soak`: sim2sim with random remote input for a chosen duration (g1_control/tools/soak.py)."""

from __future__ import annotations

import argparse


def register(subparsers) -> None:
    parser = subparsers.add_parser(
        "soak", help="sim2sim soak: g1 sim-robot + g1 deploy driven by random remote input for a while",
        description="Run g1 sim-robot (MuJoCo) and g1 deploy as separate processes on lo for --minutes of control, "
        "with random stick input on the emulated Unitree remote; report trips, deadline misses, memory growth and "
        "the LowCmd_ period percentiles at the robot. Exit 0 when nothing tripped, no tick was more than a period "
        "late and the operator stop ended it; 3 otherwise.",
        epilog="examples:\n  g1 soak --minutes 2\n  nice -n 10 g1 soak --minutes 30 --json soak.json",
        formatter_class=argparse.RawDescriptionHelpFormatter)
    from g1_control.tools.soak import add_arguments

    add_arguments(parser)
    parser.set_defaults(func=_run)


def _run(args) -> int:
    from g1_control.tools.soak import run_from_args

    return run_from_args(args)
