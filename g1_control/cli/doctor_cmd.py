"""`g1 doctor [LAUNCH]`: find the robot on the network and say what would stop a deploy, sending nothing."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

DESCRIPTION = """\
Check the way to a G1 before deploying, without sending anything: the network interface (with
--interface auto, the one NIC on 192.168.123.0/24), whether the robot's state arrives on it and on
which DDS domain, its DoF variant, other publishers of its state or writers of its commands, its
pose, joints and motors, and whether its built-in controller (the motion service) is active and
will be released. Every problem comes with its fix. Exit 0 when nothing stands in the way, 1 otherwise.
"""

EPILOG = """\
examples:
  g1 doctor --interface auto            # the robot, with the shipped robot.yaml
  g1 doctor robot --interface enp3s0
  g1 doctor sim2sim                     # g1 sim-robot on lo, domain 1
"""


def register(sub) -> None:
    parser = sub.add_parser("doctor", help="find the robot on the network and check it, sending nothing",
                            description=DESCRIPTION, epilog=EPILOG,
                            formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("file", nargs="?", default="robot",
                        help="launch file (path or shipped name) whose backend to check (default: robot)")
    parser.add_argument("--interface", help="the NIC cabled to the robot, 'lo' for g1 sim-robot, or 'auto' (the one "
                        "interface with an address on 192.168.123.0/24)")
    parser.add_argument("--domain", type=int, help="DDS domain (default: the launch file's; 0 and 1 are tried too "
                        "when it is silent)")
    parser.add_argument("--partition", help=argparse.SUPPRESS)  # tests: runs on one host never see each other
    parser.add_argument("--listen", type=float, default=3.0, metavar="S",
                        help="seconds to wait for the robot's state on each domain (default 3)")
    parser.add_argument("--json", type=Path, metavar="FILE", help="also write the findings as JSON")
    parser.set_defaults(func=_run)


def _run(args) -> int:
    from g1_control.deploy.doctor import DoctorOptions, diagnose, healthy, table
    from g1_control.launch.schema import load_launch
    from g1_control.resources import resolve_launch

    path, _ = resolve_launch(args.file)
    launch = load_launch(path)
    results = diagnose(launch, DoctorOptions(interface=args.interface, domain=args.domain, partition=args.partition,
                                             listen_s=args.listen))
    print("\n" + table(results))
    ok = healthy(results)
    print("\nnothing stands in the way of g1 deploy" if ok else "\nfix the rows marked FAIL, then run g1 doctor again")
    if args.json:
        args.json.write_text(json.dumps([r.__dict__ for r in results], indent=2) + "\n")
    return 0 if ok else 1
