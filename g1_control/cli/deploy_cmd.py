"""`g1 deploy LAUNCH.yaml`: preflight checklist, then the operator-driven state machine on a robot."""

from __future__ import annotations

import argparse
import logging
from pathlib import Path

_DESCRIPTION = """\
Bring a G1 (or `g1 sim-robot`) under the control loop a launch file describes, safely.

1. Preflight, printed as a pass/fail table with reasons; nothing is sent to the robot before it
   passes: launch file valid; policy metadata fits the robot (joint order, gains, default pose,
   DoF variant the robot reports as mode_machine); network interface exists and is up; LowState
   at >= 400 Hz with valid CRCs; IMU upright; joints inside their limits; motor temperatures
   (and battery, where reported); the operator input opens, has an e-stop and is not lost; a
   10 s lockstep MuJoCo dry run of the same launch file without a fall. Any failure refuses to
   start. A failed check you have verified yourself can be overridden with --override CHECK
   (printed and logged as an error, recorded in the report); a few cannot (invalid launch file
   or policy, missing interface, no robot, another DoF variant, a lost input).
2. The robot's built-in motion service is released (skip with --no-release-motion-service when
   you put the robot in debug mode with the remote: L2+R2 while it hangs in damping).
3. zero torque -> [start] -> ramp to the default pose (deploy.ramp_s >= 2 s) -> hold -> [run] ->
   control (the policy); [stop], e-stop, any safety fault, SIGINT/SIGTERM, the end of the control
   time or an error -> damping (kp 0, kd > 0), streamed continuously until the program exits.
   Unitree remote: start = start, A = run, B = stop, L1+R1 = e-stop, select = damp.
   Gamepad: start / A / B, LB+RB = e-stop. Keyboard: Enter / r / o, Esc = e-stop.
   --yes answers start and run automatically: unattended sim2sim only, refused unless the link
   is `g1 sim-robot` on lo (or a virtual CAN bus).

Exit status: 0 ended as planned (stop, control time over, signal); 1 refused or error; 3 a
safety fault or e-stop ended the run.

Checks (names for --override): """

_EPILOG = """\
examples:
  g1 sim-robot --lower-gantry-on-policy &              # the emulator on lo, domain 1
  g1 deploy launch/sim2sim.yaml --yes                  # sim2sim: preflight, ramp, walk, damping
  g1 deploy launch/robot.yaml                          # the robot: operator drives with the remote
  g1 deploy robot --preflight-only                     # checklist only; nothing is sent (a shipped file by name)
  g1 deploy launch/robot.yaml --no-release-motion-service   # robot already in debug mode
  g1 deploy launch/robot.yaml --override temperatures  # a check you verified yourself (logged)
  g1 deploy launch/robot.yaml --program square.yaml    # a behaviour program drives once you press run
  g1 deploy launch/sim2sim.yaml --yes --say "walk forward 1 m and turn left"   # shown; y asked on a robot
"""


def register(subparsers) -> None:
    from g1_control.deploy.preflight import CHECKS

    parser = subparsers.add_parser(
        "deploy", help="preflight-check a robot, then run a launch file on it (real G1 or g1 sim-robot)",
        description=_DESCRIPTION + ", ".join(CHECKS) + ".", epilog=_EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("file", type=Path, help="launch file with a robot backend (unitree_dds, can or serial): a path, "
                        "or a shipped launch file's name (robot, sim2sim; g1 launch --list)")
    parser.add_argument("--yes", action="store_true",
                        help="answer start and run automatically once the preflight passed (sim2sim on lo only)")
    parser.add_argument("--override", action="append", default=[], metavar="CHECK", choices=list(CHECKS),
                        help="let a failed preflight check pass (repeatable; printed and logged loudly)")
    parser.add_argument("--no-release-motion-service", dest="release", action="store_false", default=None,
                        help="do not release the robot's built-in motion service (robot already in debug mode "
                        "via the remote)")
    parser.add_argument("--interface", help="override backend.interface (e.g. lo for g1 sim-robot; auto: the one NIC on "
                        "192.168.123.0/24; g1 doctor checks the way to the robot first)")
    parser.add_argument("--domain", type=int, help="override backend.domain (robot 0, simulation 1)")
    parser.add_argument("--partition", help="override backend.partition (isolates concurrent runs on one host)")
    parser.add_argument("--duration", type=float, help="length of the control phase in seconds, then damping "
                        "(default: the launch file's duration_s, or until stopped)")
    parser.add_argument("--preflight-only", action="store_true", help="run the checklist and exit; nothing is sent")
    parser.add_argument("--out", type=Path, help="run folder root (default: the launch file's output.dir); the run "
                        "folder (per-tick log, transitions, safety events, summary) is written as the deploy goes")
    parser.add_argument("--json", type=Path, help="write the deploy report (preflight, states, link stats) as JSON")
    program = parser.add_mutually_exclusive_group()
    program.add_argument("--program", type=Path, metavar="FILE",
                         help="a behaviour program (.yaml/.json, g1_control/program/README.md) that drives the robot "
                         "once control starts; the operator device keeps start/run/stop/e-stop; dry-run in MuJoCo "
                         "first")
    program.add_argument("--say", metavar="TEXT",
                         help="an English instruction: parsed, shown, and run only after you confirm it (y); "
                         "--yes answers only on sim2sim")
    parser.set_defaults(func=_run)


def _run(args) -> int:
    from g1_control.deploy.preflight import PreflightRefused
    from g1_control.deploy.session import DeployOptions, deploy, write_report

    logging.basicConfig(level=logging.WARNING, format="%(levelname)s %(name)s: %(message)s")
    args.file = _launch_path(args.file)
    program, text = _program(args)
    options = DeployOptions(yes=args.yes, overrides=frozenset(args.override), release_motion_service=args.release,
                            interface=args.interface, domain=args.domain, partition=args.partition,
                            duration_s=args.duration, preflight_only=args.preflight_only, program=program,
                            program_text=text, out_root=args.out)
    try:
        report = deploy(args.file, options)
    except PreflightRefused as exc:
        if args.json and exc.report is not None:
            write_report(exc.report, args.json)
        raise
    if args.json:
        write_report(report, args.json)
    return 3 if report.sequence and report.fault else 0


def _launch_path(arg: Path) -> Path:
    """A shipped launch file found by name (`g1 deploy robot`), as `g1 launch` finds one; any other path
    as given, so a missing file is refused by the preflight's launch-file check and lands in its report."""
    from g1_control.errors import LaunchFileError
    from g1_control.resources import resolve_launch

    try:
        path, shipped = resolve_launch(arg)
    except LaunchFileError:
        return arg
    if shipped:
        print(f"launch file: {path}")
    return path


def _program(args):
    """(program, the English it came from) for --program / --say; (None, "") without either."""
    if args.program is not None:
        from g1_control.program import load_program

        return load_program(args.program), ""
    if args.say is not None:
        from g1_control.launch.schema import load_launch
        from g1_control.program import parse_instruction

        world = load_launch(args.file).program_world()
        return parse_instruction(args.say, places=world.names() if world.places else None), args.say
    return None, ""
