"""`g1 say "..."`: an English instruction, parsed into a behaviour program and run in simulation."""

from __future__ import annotations

import argparse
import os
from pathlib import Path

DEFAULT_LAUNCH = "sim_program"
"""The launch file whose loop runs the program (its input is replaced by the instruction)."""
SCENE_LAUNCH = "sim_scene_program"
"""... and the one when the instruction names a place: tables, a box, a platform, a door; goals
(reach, pick, place, step) executed by the goal generator and the tracking layer
(launch/inputs.py:program_launch_name)."""


def register(subparsers) -> None:
    parser = subparsers.add_parser(
        "say",
        help="tell the simulated robot what to do in English (parsed into a behaviour program)",
        description="Parse an English instruction into a behaviour program (g1_control/program/README.md: "
        "walk, turn, wait, styles, heights, reach, pick, place, step up/down; then/and/while/after/until/"
        "twice), print the program, run it in MuJoCo and print each step's outcome as it finishes: the "
        "runner's own (from the robot's estimate: IMU yaw and leg odometry) and the ground-truth verdict "
        "(distance within 10 %%, heading within 10 degrees, ...). Places the instruction names must be in "
        "the launch file's places (or its scene). Words the parser does not know are named with the "
        "closest known ones.",
        epilog="examples:\n"
        '  g1 say "walk forward two meters, then turn left ninety degrees and wave"\n'
        '  g1 say "take three steps back and turn around" --dry-run      # the program only\n'
        '  g1 say "walk forward 1 m while waving" --video                 # run folder with video.mp4\n'
        '  g1 say "walk to the door" --launch my_room.yaml                # places from a launch file\n'
        "exit status (as g1 launch's): 0 every step met by ground truth, no fall, no safety trip; 1 a fall\n"
        "(whatever tripped before), a step missed, or a refused instruction; 3 the safety layer tripped\n"
        "(damping) and the robot did not fall",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("instruction", help="the instruction, in quotes")
    parser.add_argument("--dry-run", action="store_true", help="print the program and exit (nothing runs)")
    parser.add_argument("--launch", default=None, metavar="FILE",
                        help=f"launch file whose loop (and places) runs the program (default: {DEFAULT_LAUNCH}; "
                        f"{SCENE_LAUNCH}, a scene with tables, a box, a platform and a door, when the instruction "
                        "names a place)")
    parser.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE",
                        help="override a launch-file key (as g1 launch --set)")
    parser.add_argument("--pose", choices=("estimator", "ground_truth"),
                        help="what the runner steers by (default: the launch file's input.pose, normally the "
                        "robot's own estimate)")
    parser.add_argument("--out", type=Path, help="run folder root (default: the launch file's output.dir)")
    video = parser.add_mutually_exclusive_group()
    video.add_argument("--video", dest="video", action="store_true", default=None, help="render video.mp4")
    video.add_argument("--no-video", dest="video", action="store_false", help="skip the video")
    parser.add_argument("--viewer", choices=("auto", "on", "off"), default="off",
                        help="MuJoCo viewer (default off; auto opens it when a display exists)")
    parser.add_argument("--json", type=Path, help="write the program and each step's outcome as JSON")
    parser.set_defaults(func=_run)


def say_program(text: str, launch):
    """Parse `text` against the places of `launch` (its input.places; none: the parser's default
    place names, so a dry run can show any program). Raises InstructionError."""
    from g1_control.launch.inputs import program_world
    from g1_control.program import parse_instruction

    world = program_world(launch)
    return parse_instruction(text, places=world.names() if world.places else None), world


def _run(args) -> int:
    from g1_control.errors import LaunchFileError
    from g1_control.launch.schema import load_launch
    from g1_control.program import ProgramError
    from g1_control.resources import resolve_launch

    name = args.launch
    if name is None:  # a scene when the instruction names a place (parsed with the default place words)
        from g1_control.launch.inputs import program_launch_name
        from g1_control.program import parse_instruction

        name = program_launch_name(parse_instruction(args.instruction))
    path, _ = resolve_launch(name)
    launch = load_launch(path, overrides=args.overrides)
    program, world = say_program(args.instruction, launch)
    print(f'"{args.instruction}"\n' + program.describe(), flush=True)
    if args.dry_run:
        if args.json:
            import json

            args.json.write_text(json.dumps(program.to_dict(), indent=2) + "\n")
        return 0
    try:
        program.validate(world)
    except ProgramError as exc:
        raise LaunchFileError(f"{exc}; name a launch file with these places or a scene (--launch FILE, "
                              "input.places)") from None
    launch.name = "say"
    launch.input.type = "program"
    launch.input.program = [s.to_dict() for s in program.steps]
    launch.input.instruction = ""
    if args.pose:
        launch.input.pose = args.pose
    from g1_control.launch.inputs import make_program_input
    from g1_control.launch.runner import run
    from g1_control.program.device import describe_record
    from g1_control.report.results import fall_text, program_summary

    device = make_program_input(launch, program, on_record=lambda r: print("  " + describe_record(r), flush=True))
    viewer = args.viewer == "on" or (args.viewer == "auto" and bool(os.environ.get("DISPLAY")))
    if viewer:
        launch.backend.mode = "wallclock"
    print(f"running in MuJoCo (steering by {launch.input.pose}; judged from ground truth):", flush=True)
    result = run(launch, out_root=args.out or Path(launch.output.dir), video=args.video, progress=False,
                 viewer=viewer, input_device=device)
    summary = result.extra.get("program", {"steps": [], "finished": False, "pose": launch.input.pose})
    print(program_summary(summary).splitlines()[0])
    for step in summary["steps"]:  # goal steps: judged after the run from the execution layer's ground truth
        if "goal_id" in step and "verdict" in step:
            v = step["verdict"]
            print(f"  {step['label']}. {step['description']} (ground truth): {v['text']} {'OK' if v['ok'] else 'MISSED'}")
    print(f"{fall_text(result.fall)}; {result.duration_s:.1f} s simulated in {result.wall_s:.1f} s wall")
    if result.run_dir is not None:
        print(f"run folder: {result.run_dir}" + (f" (video: {Path(result.video).name})" if result.video else ""))
    if args.json:
        import json

        args.json.write_text(json.dumps({"instruction": args.instruction, "program": program.to_dict(),
                                         "fell": result.fell, **summary}, indent=2, default=float) + "\n")
    return say_exit_status(result, summary)


def say_exit_status(result, summary: dict) -> int:
    """g1 launch's exit status (cli/launch_cmd.py) for a program run: EXIT_FAILED on a fall (whatever tripped
    before it), else EXIT_TRIPPED on an unplanned safety trip, else EXIT_FAILED when the program did not
    finish or a step was missed by ground truth, else EXIT_OK."""
    from g1_control.cli.launch_cmd import EXIT_FAILED, EXIT_OK, EXIT_TRIPPED
    from g1_control.loop.control_loop import first_fault

    if result.fell:
        return EXIT_FAILED
    if first_fault(result.events) is not None:
        return EXIT_TRIPPED
    met = all(s.get("verdict", {}).get("ok", s["status"] == "completed") for s in summary["steps"])
    return EXIT_OK if (summary["finished"] and met) else EXIT_FAILED
