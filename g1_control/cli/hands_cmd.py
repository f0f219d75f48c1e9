"""`g1 hands`: the Dex3-1 hands over DDS: their stream and fingers (status), a force-limited grasp."""

from __future__ import annotations

import argparse
import json
import sys
import time


def register(subparsers) -> None:
    parser = subparsers.add_parser(
        "hands", help="the Dex3-1 hands over DDS: status, force-limited grasp",
        description="Talk to the G1's Dex3-1 hands (HandCmd_/HandState_ on rt/dex3/left|right/cmd|state) the way "
        "`g1 deploy` does with backend.hands: dex3: every command through the hands' safety layer (URDF limits, "
        "speed, gains; damping on NaN or a stale, frozen or faulted hand).",
        epilog="examples:\n  g1 sim-robot --hands dex3 &             # emulated hands on lo, domain 1\n"
        "  g1 hands status\n  g1 hands grasp --side right --torque-limit 0.5\n"
        "  g1 hands grasp --side left --interface eth0 --domain 0   # a real robot: hands free of objects and people",
        formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="hands_command", required=True)
    status = sub.add_parser("status", help="each hand's stream rate and finger angles against their limits",
                            description="Listen to both hands for --seconds and print each one's HandState_ rate, "
                            "whether its samples change, and every finger's angle against its URDF limits.")
    grasp = sub.add_parser(
        "grasp", help="close one hand until each finger feels the object (torque limit), then release",
        description="Close one hand's fingers at --speed until each one's measured torque reaches half of "
        "--torque-limit (it touched), hold at 0.9 of the limit for --hold-s, then damp (kp 0). Prints each "
        "finger's stop (touched the object / closed fully), angle and torque.")
    for p in (status, grasp):
        p.add_argument("--interface", default="lo", help="network interface (default lo: `g1 sim-robot --hands dex3`)")
        p.add_argument("--domain", type=int, default=1, help="DDS domain id (default 1; the robot uses 0)")
        p.add_argument("--partition", help="DDS partition (only to isolate concurrent runs on one host)")
        p.add_argument("--json", action="store_true", help="print one JSON object instead of a table")
    status.add_argument("--seconds", type=float, default=1.0, help="how long to listen (default 1)")
    grasp.add_argument("--side", choices=("left", "right"), required=True)
    grasp.add_argument("--torque-limit", type=float, default=0.5, metavar="NM",
                       help="no finger squeezes harder than this (N m; default 0.5, at most the motors' 1.4)")
    grasp.add_argument("--speed", type=float, metavar="RADPS",
                       help="closing speed (default: 3 rad/s per N m of --torque-limit, at most 1.5)")
    grasp.add_argument("--hold-s", type=float, default=1.0, help="how long to hold before releasing (default 1 s)")
    grasp.add_argument("--timeout-s", type=float, default=5.0, help="give up closing after this long (default 5 s)")
    parser.set_defaults(func=_run)


def _run(args) -> int:
    from g1_control.hardware.hand_link import Dex3HandLink

    with Dex3HandLink(args.interface, args.domain, partition=args.partition) as link:
        if args.hands_command == "status":
            return _status(link, args)
        return _grasp(link, args)


def _status(link, args) -> int:
    from g1_control.errors import RobotNotConnectedError
    from g1_control.robot import dex3

    try:
        link.wait_for_state(dex3.SIDES, max(args.seconds, 1.0))
    except RobotNotConnectedError as exc:
        print(f"g1 hands: {exc}", file=sys.stderr)
        return 1
    time.sleep(args.seconds)
    out = {}
    for side in dex3.SIDES:
        st, state, lim = link.stats(side, args.seconds), link.read(side), dex3.hand_limits(side)
        out[side] = {"rate_hz": st.state_rate_hz, "changing": st.distinct_states > 1, "fingers": {
            name: {"q_rad": float(state.q_rad[i]), "lower": float(lim.q_min_rad[i]), "upper": float(lim.q_max_rad[i]),
                   "tau_nm": float(state.tau_nm[i])} for i, name in enumerate(dex3.joint_names(side))}}
    if args.json:
        print(json.dumps(out))
        return 0
    for side, row in out.items():
        print(f"{side}: {row['rate_hz']:.0f} Hz, samples {'changing' if row['changing'] else 'FROZEN'}")
        for name, f in row["fingers"].items():
            inside = f["lower"] - 0.02 <= f["q_rad"] <= f["upper"] + 0.02
            print(f"  {name:<26} {f['q_rad']:+.3f} rad  [{f['lower']:+.3f}, {f['upper']:+.3f}]"
                  f"{'' if inside else '  OUTSIDE'}  tau {f['tau_nm']:+.3f} N m")
    return 0


def _grasp(link, args) -> int:
    from g1_control.errors import RobotNotConnectedError
    from g1_control.robot import dex3
    from g1_control.safety.hands import GuardedHands
    from g1_control.trackers.grasp import ForceLimitedGrasp

    try:
        grasp = ForceLimitedGrasp(args.side, torque_limit_nm=args.torque_limit, closing_speed_radps=args.speed)
        link.wait_for_state((args.side,), 2.0)
    except (ValueError, RobotNotConnectedError) as exc:
        print(f"g1 hands grasp: {exc}", file=sys.stderr)
        return 1
    time.sleep(0.1)  # a few samples, so that the hands' safety has seen them change
    guarded = GuardedHands(link)
    t0 = time.monotonic()
    done_s = None
    peak = 0.0
    while guarded.tripped is None:
        now = time.monotonic()
        state = link.read(args.side)
        guarded.write(args.side, grasp.act(state, now))
        peak = max(peak, float(abs(state.tau_nm).max()))
        if done_s is None and grasp.done:
            done_s = now - t0
        if (done_s is not None and now - t0 > done_s + args.hold_s) or (done_s is None and now - t0 > args.timeout_s):
            break
        time.sleep(0.01)
    state = link.read(args.side)
    fingers = {name: {"stop": "touched" if grasp.touched[i] else "closed" if grasp.closed[i] else "-",
                      "q_rad": float(state.q_rad[i]), "tau_nm": float(state.tau_nm[i])}
               for i, name in enumerate(dex3.joint_names(args.side))}
    result = {"side": args.side, "done_s": done_s, "tripped": guarded.tripped, "torque_limit_nm": args.torque_limit,
              "peak_measured_tau_nm": peak, "fingers": fingers}
    link.damp()
    if args.json:
        print(json.dumps(result))
    else:
        verdict = (f"closed in {done_s:.2f} s" if done_s is not None else f"not closed within {args.timeout_s:.1f} s")
        print(f"{args.side} hand: {verdict}; peak measured torque {peak:.3f} N m (limit {args.torque_limit:.3f})"
              + (f"; TRIPPED: {guarded.tripped}" if guarded.tripped else "") + "; released (damping)")
        for name, f in fingers.items():
            print(f"  {name:<26} {f['stop']:<8} {f['q_rad']:+.3f} rad  tau {f['tau_nm']:+.3f} N m")
    return 0 if done_s is not None and guarded.tripped is None else 1
