"""`g1 sim-robot`: the G1 emulator on DDS loopback (MuJoCo physics behind rt/lowcmd, rt/lowstate)."""

from __future__ import annotations

import argparse
import signal
import sys
import time
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from g1_control.interfaces import Backend


def register(subparsers) -> None:
    parser = subparsers.add_parser(
        "sim-robot",
        help="emulate a G1 on DDS loopback (for sim2sim with the robot code path)",
        description="Run the MuJoCo G1 behind the robot's own DDS protocol on loopback: LowState_ at 500 Hz "
        "with CRC, LowCmd_ honoured only with a valid CRC and the reported mode_machine, motor enable, and a "
        "motion service whose built-in controller holds the robot until released. Point the robot path at "
        "it with the same interface and domain (e.g. `g1 deploy launch/sim2sim.yaml`).",
        epilog="examples:\n  g1 sim-robot                      # lo, domain 1, until Ctrl-C\n"
        "  g1 sim-robot --seconds 30 --physics mock\n"
        "  g1 sim-robot --control-stdin      # faults / remote buttons by name on stdin (test harnesses)\n"
        "  g1 sim-robot --lower-gantry-on-policy   # sim2sim with g1 deploy launch/sim2sim.yaml --yes\n"
        "  g1 sim-robot --mode-machine 4 --lower-gantry-on-policy   # the 23-DoF G1 (g1 deploy launch/sim2sim_23dof.yaml)\n"
        "  g1 sim-robot --lower-gantry-on-policy --mocap --mocap-noise-m 0.02 --mocap-latency-s 0.1   # sim2sim_mocap.yaml\n"
        "  g1 sim-robot --lower-gantry-on-policy --randomize 3   # a randomised G1 (masses, CoM, motor strength, "
        "latency, foot friction; drawn from seed 3)\n"
        "  g1 sim-robot --lower-gantry-on-policy --scene launch/sim2sim_box.yaml --perception-noise-m 0.02 "
        "--perception-latency-s 0.1 --perception-dropout 0.1",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("--interface", default="lo", help="network interface; loopback only (default lo)")
    parser.add_argument("--domain", type=int, default=1, help="DDS domain id (default 1, as simulators use)")
    parser.add_argument("--partition", help="DDS partition (only to isolate concurrent runs on one host)")
    parser.add_argument("--physics", choices=("mujoco", "mock"), default="mujoco",
                        help="mujoco: the G1 scene; mock: rigid joints on a gantry (fast start, no falls)")
    parser.add_argument("--gantry", action="store_true",
                        help="hang the MuJoCo robot from an elastic band (first-run practice; a plain PD hold "
                        "falls without it)")
    parser.add_argument("--lower-gantry-on-policy", action="store_true",
                        help="hang the robot on the gantry (as --gantry) and lower it when the policy takes over: "
                        "when stiff leg targets held still for 0.3 s (the deploy's hold) start to move. For sim2sim "
                        "with `g1 deploy`, whose zero-torque/ramp/hold phases need the gantry")
    parser.add_argument("--mode", choices=("robot", "unitree_mujoco"), default="robot",
                        help="robot: the G1's protocol (default); unitree_mujoco: play Unitree's MuJoCo simulator "
                        "(LowState_ with crc, tick and mode_machine 0 at 200 Hz, PD torque computed when a LowCmd_ "
                        "arrives and held, no motion service), for g1 deploy with backend.simulator: unitree_mujoco")
    parser.add_argument("--mocap", action="store_true",
                        help="also publish a motion-capture pose of the pelvis from the simulator's ground truth "
                        "(geometry_msgs/PoseStamped on rt/<--mocap-topic>, frame 'mocap' = the scene frame), for a "
                        "launch file's estimation.external_pose")
    _add_feed_arguments(parser, "mocap", "mocap/pose", 100.0, "pose")
    parser.add_argument("--scene", metavar="FILE",
                        help="build this launch file's scene (tables, platforms, boxes) in the MuJoCo physics and "
                        "publish its boxes and platforms (if any) as perception sees them (g1_msgs ObjectPoses_ on "
                        "rt/<--perception-topic>, PlatformPoses_ on rt/<--perception-topic>/platforms, each in the robot's "
                        "heading frame; the --perception-* noise, latency and dropouts apply to both); the exit report "
                        "gives the boxes' and platforms' ground truth")
    _add_feed_arguments(parser, "perception", "perception/objects", 10.0, "frame")
    parser.add_argument("--record", metavar="FILE", help="write the ground truth (hand points, sole points, boxes; "
                        "50 Hz, stamped with the host's monotonic clock) to this .npz at exit, for judging the goals of a "
                        "deploy's report against it (python -m g1_control.tools.judge_sim2sim); --physics mujoco")
    parser.add_argument("--mode-machine", type=int, default=5,
                        help="the G1 variant to emulate and report: 4 = 23-DoF (no waist roll/pitch, no wrist "
                        "pitch/yaw: MuJoCo builds it without those joints), 5 = 29-DoF (default), 6 = 29-DoF with "
                        "the waist locked (--physics mock reports any value)")
    _add_randomize_arguments(parser)
    parser.add_argument("--no-builtin", action="store_true",
                        help="start with no built-in controller (as after debug mode on the remote)")
    parser.add_argument("--rt-priority", type=int, default=30, metavar="N",
                        help="SCHED_RR priority (default 30; 0: normal scheduling): the emulated robot keeps its 500 Hz "
                        "on a busy host, as the robot's own computer would (needs root, else nice -10 with a warning)")
    parser.add_argument("--hands", choices=("none", "dex3"), default="none",
                        help="dex3: emulate the two Dex3-1 hands too (HandState_ on rt/dex3/left|right/state at "
                        "100 Hz, HandCmd_ applied from rt/dex3/left|right/cmd; a per-finger motor model, "
                        "g1_control/sim/dex3_hands.py), for launch files with backend.hands: dex3")
    parser.add_argument("--hand-object", type=float, metavar="CLOSURE",
                        help="with --hands dex3: an object in each hand that every closing finger touches at this "
                        "fraction of its travel (0 open .. 1 closed), for trying `g1 hands grasp`")
    parser.add_argument("--seconds", type=float, help="stop after this long (default: until Ctrl-C)")
    parser.add_argument("--control-stdin", action="store_true",
                        help="read fault names and remote commands ('press start', 'press A', 'stick ly 0.5', "
                        "'press L1+R1') from stdin, answer JSON lines (see g1_control/sim/emulator.py)")
    parser.set_defaults(func=_run)


def _add_feed_arguments(parser, name: str, topic: str, rate_hz: float, sample: str) -> None:
    """--NAME-topic/-rate-hz/-noise-m/-noise-deg/-latency-s/-dropout/-seed of a simulated sensor feed."""
    parser.add_argument(f"--{name}-topic", default=topic, help=f"its ROS 2 topic (default {topic})")
    parser.add_argument(f"--{name}-rate-hz", type=float, default=rate_hz, help=f"{sample}s per second (default {rate_hz:g})")
    parser.add_argument(f"--{name}-noise-m", type=float, default=0.0, help="position noise, std per axis (m)")
    parser.add_argument(f"--{name}-noise-deg", type=float, default=0.0, help="heading noise, std (deg)")
    parser.add_argument(f"--{name}-latency-s", type=float, default=0.0, help=f"each {sample} is sent this late (s)")
    parser.add_argument(f"--{name}-dropout", type=float, default=0.0, help=f"probability that a {sample} is lost (0..1)")
    parser.add_argument(f"--{name}-seed", type=int, default=0, help="seed of the noise and dropouts")


def _add_randomize_arguments(parser) -> None:
    """--randomize SEED and the ranges it draws from (g1_control/sim/randomize.py; defaults as there)."""
    from g1_control.sim.randomize import RandomizeConfig

    d = RandomizeConfig()
    parser.add_argument("--randomize", type=int, metavar="SEED",
                        help="MuJoCo: a domain-randomised G1 drawn from SEED (link masses, CoM offsets, motor "
                        "strength, command latency, foot friction), printed at start and in the exit report; the "
                        "same seed gives the same robot (as a launch file's backend.randomize)")
    for flag, default, what in (("mass-scale", d.mass_scale, "factor on each link's mass"),
                                ("motor-strength", d.motor_strength, "factor on each motor's torque and limit"),
                                ("latency-s", d.latency_s, "command latency (s)"),
                                ("foot-friction", d.foot_friction, "sliding friction of the feet")):
        parser.add_argument(f"--randomize-{flag}", type=float, nargs=2, metavar=("LOW", "HIGH"), default=list(default),
                            help=f"with --randomize: range of the {what} (default {default[0]:g} {default[1]:g})")
    parser.add_argument("--randomize-com-offset-m", type=float, default=d.com_offset_m, metavar="M",
                        help=f"with --randomize: largest CoM offset per link (default {d.com_offset_m:g} m)")


def _randomize_config(args):
    """The RandomizeConfig of --randomize (None without it); LaunchFileError on a bad range."""
    from g1_control.sim.randomize import RandomizeConfig

    if args.randomize is None:
        return None
    config = RandomizeConfig(seed=args.randomize, mass_scale=tuple(args.randomize_mass_scale),
                             com_offset_m=args.randomize_com_offset_m,
                             motor_strength=tuple(args.randomize_motor_strength),
                             latency_s=tuple(args.randomize_latency_s), foot_friction=tuple(args.randomize_foot_friction))
    config.validate("--randomize")
    return config


def _feed_config(args, name: str):
    """The MocapConfig of the feed `name` (its arguments from _add_feed_arguments)."""
    import math

    from g1_control.sim.mocap import MocapConfig

    a = vars(args)
    return MocapConfig(a[f"{name}_rate_hz"], a[f"{name}_noise_m"], math.radians(a[f"{name}_noise_deg"]),
                       a[f"{name}_latency_s"], a[f"{name}_dropout"], a[f"{name}_seed"])


def _run(args) -> int:
    from g1_control.errors import G1ControlError, LaunchFileError
    from g1_control.loop.priority import frozen_heap, realtime
    from g1_control.sim.emulator import RobotEmulator

    if args.record and args.physics != "mujoco":
        print("g1 sim-robot: --record needs --physics mujoco (the ground truth is MuJoCo's)", file=sys.stderr)
        return 2
    physics: Backend
    scene = start_in_scene = None
    try:
        randomize = _randomize_config(args)
    except LaunchFileError as exc:  # "--randomize.mass_scale: ..." names the flag --randomize-mass-scale
        key, _, problem = str(exc).partition(": ")
        flag = "--randomize" if key.endswith(".seed") else key.replace(".", "-").replace("_", "-")
        print(f"g1 sim-robot: {flag}: {problem}", file=sys.stderr)
        return 2
    if randomize is not None and args.physics != "mujoco":
        print("g1 sim-robot: --randomize needs --physics mujoco", file=sys.stderr)
        return 2
    realtime(args.rt_priority)
    if args.scene:
        from g1_control.launch.schema import load_launch

        if args.physics != "mujoco":
            print("g1 sim-robot: --scene needs --physics mujoco", file=sys.stderr)
            return 2
        try:
            launch = load_launch(args.scene)
            scene = launch.scene
            external = launch.estimation.external_pose
            # the launch file's scene.robot_start: the mocap speaks the scene's frame, as its calibration would
            start_in_scene = external.start_in_scene if external is not None and external.frame == "scene" else None
        except LaunchFileError as exc:
            print(f"g1 sim-robot: --scene: {exc}", file=sys.stderr)
            return 2
    if args.physics == "mujoco":
        from g1_control.robot import g1
        from g1_control.sim.mujoco_backend import MujocoBackend, MujocoConfig

        try:
            variant = g1.variant_for_mode_machine(args.mode_machine).name
        except ValueError as exc:
            raise G1ControlError(f"--mode-machine: {exc}") from None
        mujoco: MujocoBackend
        if args.mode == "unitree_mujoco":
            from g1_control.sim.unitree_mujoco import PHYSICS_DT_S, HeldTorqueMujoco

            physics = mujoco = HeldTorqueMujoco(MujocoConfig(lockstep=True, physics_dt_s=PHYSICS_DT_S, variant=variant,
                                                             randomize=randomize), scene=scene)
        else:
            physics = mujoco = MujocoBackend(MujocoConfig(lockstep=True, variant=variant, randomize=randomize,
                                                          hard_joint_stops=True), scene=scene)
        if mujoco.draw is not None:
            print(f"g1 sim-robot: {mujoco.describe()}", file=sys.stderr, flush=True)
        if args.gantry or args.lower_gantry_on_policy:
            from g1_control.sim.emulator import Gantry

            physics = Gantry(mujoco, physics_dt_s=mujoco.config.physics_dt_s,
                             lower_on_policy=args.lower_gantry_on_policy)
    else:
        from g1_control.sim.mock_robot import MockG1

        physics = MockG1(mode_machine=args.mode_machine)
    emulator = RobotEmulator(physics, args.interface, args.domain, partition=args.partition,
                             builtin_mode="" if args.no_builtin else "ai", mode=args.mode)
    try:
        if args.mocap:
            emulator.publish_mocap(_feed_config(args, "mocap"), args.mocap_topic, start_in_scene)
        if scene is not None and (scene.boxes or scene.platforms):  # tables only: nothing to perceive
            emulator.publish_perception(mujoco, _feed_config(args, "perception"), args.perception_topic)
    except ValueError as exc:
        emulator.close()
        print(f"g1 sim-robot: {exc}", file=sys.stderr)
        return 2
    recorder = emulator.record_ground_truth(mujoco) if args.record else None
    emulator.start()
    hands = None
    if args.hands == "dex3":
        from g1_control.sim.dex3_hands import Dex3HandsEmulator

        hands = Dex3HandsEmulator(args.interface, args.domain, partition=args.partition).start()
        if args.hand_object is not None:
            for side in hands.hands:
                hands.hold_object(side, args.hand_object)
    elif args.hand_object is not None:
        print("g1 sim-robot: --hand-object needs --hands dex3", file=sys.stderr)
        emulator.close()
        return 2
    stop = {"now": False}

    def _stop(signum, frame):
        stop["now"] = True

    signal.signal(signal.SIGTERM, _stop)
    with frozen_heap():  # the 500 Hz robot loop never waits for a full collection of the startup heap
        played = ", as Unitree's unitree_mujoco" if args.mode == "unitree_mujoco" else ""
        print(f"g1 sim-robot: emulating a G1 ({args.physics}{played}, mode_machine {args.mode_machine}"
              + (", Dex3-1 hands" if hands is not None else "") + f") on interface {args.interface}, "
              f"domain {args.domain}"
              + (f", partition {args.partition}" if args.partition else ""), file=sys.stderr, flush=True)
        print("ready", flush=True)
        try:
            if args.control_stdin:
                emulator.serve_stdin()
            else:
                end = time.monotonic() + args.seconds if args.seconds else float("inf")
                while not stop["now"] and time.monotonic() < end:
                    time.sleep(0.05)
        except KeyboardInterrupt:
            pass
        finally:
            report = emulator.report()
            emulator.close()
            if recorder is not None:
                import numpy as np

                np.savez_compressed(args.record, **recorder.arrays())  # type: ignore[arg-type]
            if hands is not None:
                hand_states, hand_commands = sum(hands.states_sent.values()), sum(hands.commands_applied.values())
                hands.close()
                print(f"g1 sim-robot: hands: {hand_states} HandState_ sent, {hand_commands} HandCmd_ applied",
                      file=sys.stderr)
    print(f"g1 sim-robot: {report['states_sent']} states sent, {report['commands_applied']} commands applied, "
          f"{report['bad_crc']} bad CRC, {report['wrong_mode_machine']} wrong mode_machine, "
          f"{report['ignored_while_builtin_active']} ignored while the built-in controller ran", file=sys.stderr)
    if "boxes_w_m" in report:
        boxes = ", ".join(f"{name} ({x:+.3f}, {y:+.3f}, {z:+.3f})" for name, (x, y, z) in report["boxes_w_m"].items())
        platforms = "".join(f"; platform {name} at ({p['center_xy_m'][0]:+.3f}, {p['center_xy_m'][1]:+.3f}), "
                            f"{p['height_m']:.2f} m high" for name, p in report["platforms_w_m"].items())
        print(f"g1 sim-robot: ground truth at exit: boxes {boxes or 'none'}{platforms}; pelvis {report['base_pos_w_m']}",
              file=sys.stderr)
    if "mocap" in report:
        m = report["mocap"]
        print(f"g1 sim-robot: motion capture: {m['sent']} poses sent, {m['dropped']} of {m['measured']} dropped",
              file=sys.stderr)
    return 0
