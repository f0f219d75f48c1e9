"""`g1 input`: open an input device and show the Command it produces, live.

For checking a gamepad or the keyboard before a launch: which path, which buttons do what,
whether the sticks rest at zero. Runs no robot.
"""

from __future__ import annotations

import argparse
import sys
import time


def register(subparsers) -> None:
    parser = subparsers.add_parser(
        "input",
        help="show the commands a gamepad or the keyboard produces (no robot)",
        description="Open a teleop input device with its default mapping (or one from a YAML file) and\n"
        "print the Command it produces at a fixed rate: velocities, style, pelvis height, and each\n"
        "button action as it fires. Stops after --seconds, on Ctrl-C, or when the device is lost\n"
        "(unplugged, terminal closed). The Unitree remote needs the robot's state stream and is\n"
        "checked through a launch instead. Default mappings: g1_control/teleop/README.md.",
        epilog="examples:\n  g1 input gamepad --path /dev/input/by-id/usb-Microsoft_Controller-event-joystick\n"
        "  g1 input gamepad --path auto --mapping my_pad.yaml\n  g1 input keyboard",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("type", choices=("gamepad", "keyboard"), help="device type")
    parser.add_argument("--path", help="gamepad: evdev node or 'auto'; keyboard: a tty (default: this terminal)")
    parser.add_argument("--mapping", metavar="YAML", help="a file holding the device's `mapping:` section")
    parser.add_argument("--rate", type=float, default=50.0, help="polls per second (default 50)")
    parser.add_argument("--seconds", type=float, default=float("inf"), help="stop after this long (default: Ctrl-C)")
    parser.set_defaults(func=_run)


def _run(args) -> int:
    from g1_control.errors import LaunchFileError
    from g1_control.teleop.factory import make_input_device

    config: dict = {"type": args.type}
    if args.path:
        config["path"] = args.path
    elif args.type == "gamepad":
        config["path"] = "auto"
    if args.mapping:
        import yaml

        try:
            with open(args.mapping) as fh:
                config["mapping"] = yaml.safe_load(fh)
        except (OSError, yaml.YAMLError) as exc:
            raise LaunchFileError(f"--mapping {args.mapping}: cannot read: {exc}") from None
    if not args.rate > 0:
        raise LaunchFileError(f"--rate is {args.rate}; expected a positive number of polls per second")
    device = make_input_device(config, "input")
    out = sys.stdout
    print(f"{device.name}: polling at {args.rate:g} Hz; Ctrl-C to stop", file=out, flush=True)
    period = 1.0 / args.rate
    start = next_tick = time.monotonic()
    try:
        while time.monotonic() - start < args.seconds:
            command = device.poll()
            height = "-" if command.pelvis_height_m is None else f"{command.pelvis_height_m:.3f}"
            line = (f"vx {command.vx_mps:+.2f} m/s  vy {command.vy_mps:+.2f} m/s  wz {command.wz_radps:+.2f} rad/s  "
                    f"style {command.style}  pelvis {height} m")
            if command.buttons:
                print(f"\r{line}  [{', '.join(sorted(command.buttons))}]", file=out, flush=True)
            else:
                print(f"\r{line}", end="", file=out, flush=True)
            if device.lost:
                print(f"\ndevice lost: {device.lost_reason}", file=out, flush=True)
                return 1
            next_tick += period
            time.sleep(max(0.0, next_tick - time.monotonic()))
    finally:
        device.close()
        stats = device.stats
        print(f"\n{stats.actions} actions, {stats.nan_axis_values} NaN and {stats.clamped_axis_values} "
              "out-of-range axis values", file=out, flush=True)
    return 0
