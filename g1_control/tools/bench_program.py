"""`g1 bench program`: multi-step English instructions run in MuJoCo, every step judged from ground truth.

Each instruction is parsed, run through the one loop builder (launch/sim_program.yaml: the walking
policy, lockstep MuJoCo) with the runner steering by the robot's own estimate (IMU yaw, leg
odometry), and every step judged by g1_control/program/judge.py from the simulator's pose: a walk
within 10 % of its distance, a turn within 10 degrees, a height within 5 cm, goals by the
execution layer's verdict. Falls are the loop's fall monitor's (ground truth). Prints one line
per step and a table per instruction; exits 1 on a fall or a missed step.

    g1 bench program                 # the 20 instructions below (15 walk/turn/style/height/wait, 5 with goals)
    g1 bench program --only 3,7      # some of them (1-based)
    g1 bench program --json out.json
    g1 bench program --jobs 2        # instructions in 2 processes, or --ray local / HOST:PORT (the same verdicts)
"""

from __future__ import annotations

import json
import time
from collections import Counter
from pathlib import Path
from typing import Literal

INSTRUCTIONS: tuple[str, ...] = (
    "walk forward 1 meter, turn left 90 degrees, walk forward 1 meter, then turn right 90 degrees",
    "walk forward two meters, then turn left ninety degrees and wave for 3 seconds, then walk backward 1 meter",
    "walk backward 1 meter, turn around, walk forward 1 meter and look around for 3 seconds",
    "walk forward 1 m while waving, turn right 90 degrees, walk forward 1 m with your arms out, then stand still "
    "for 2 seconds",
    "walk forward 1 meter and turn left 90 degrees, repeat that 4 times",
    "crouch, walk forward 1 meter, stand up and turn left 90 degrees",
    "walk forward 2 meters slowly, turn right 90 degrees quickly, walk forward 1 meter quickly, then dance for 3 "
    "seconds",
    "spin left 360 degrees, walk forward 1 meter, spin right 360 degrees and wave",
    "switch to the guard style, walk forward 1.5 meters, turn around, walk forward 1.5 meters and switch to the "
    "default style",
    "walk forward 3 feet, turn left a quarter turn, walk forward 3 feet, then make a half turn",
    "walk to the left 1 meter, walk forward 1 meter, walk to the right 1 meter and walk backward 1 meter",
    "lower your pelvis to 0.68 meters, walk forward 1 meter, raise your pelvis to 0.75 meters and turn right 60 "
    "degrees",
    "take three steps forward, turn left 90 degrees twice, walk forward 1 meter and come back",
    "swing your arms while walking forward 2 meters, turn around while looking around, then walk forward 2 meters "
    "and raise your arms",
    "sidestep left half a meter, then sidestep right half a meter, turn left 30 degrees and turn right 30 degrees",
    # goals, in launch/sim_scene_program.yaml (a table with a 2 kg box, another table, a 0.15 m platform)
    "walk forward half a meter, turn left 30 degrees, pick up the box and put it on the other table",
    "turn right 90 degrees, walk forward 1 meter, step onto the platform, wait 2 seconds and step down",
    "reach forward 20 cm with your right hand, walk backward half a meter, reach 15 cm to the left with your left "
    "hand and turn left 45 degrees",
    "walk to the table, pick up the box, bring it to the other table, then walk backward half a meter",
    "step onto the platform, step down, turn left 90 degrees and wave for 3 seconds",
)


def run_instruction(text: str, launch_name: str | None = None,
                    pose: Literal["estimator", "ground_truth"] = "estimator") -> dict:
    """Parse and run one instruction; the per-step records (ground-truth verdicts), fall, times.
    launch_name: default sim_program, or sim_scene_program when the instruction names a place."""
    from g1_control.launch.inputs import make_program_input, program_launch_name
    from g1_control.launch.runner import run
    from g1_control.launch.schema import load_launch
    from g1_control.program import parse_instruction
    from g1_control.program.device import record_dict
    from g1_control.resources import resolve_launch

    launch = load_launch(resolve_launch(launch_name or program_launch_name(parse_instruction(text)))[0])
    world = launch.program_world()
    c0 = time.thread_time()
    program = parse_instruction(text, places=world.names() if world.places else None)
    parse_ms = (time.thread_time() - c0) * 1e3
    launch.name, launch.input.type = "bench_program", "program"
    launch.input.program, launch.input.instruction, launch.input.pose = [s.to_dict() for s in program.steps], "", pose
    device = make_program_input(launch, program)
    result = run(launch, progress=False, video=False, input_device=device)
    steps = [record_dict(r) for r in device.records]
    return {"instruction": text, "launch": launch.name, "program": program.describe().splitlines(),
            "primitives": program.count_primitives(), "goals": result.extra.get("goals", []),
            "parse_cpu_ms": parse_ms, "fell": result.fell, "fall": result.fall,
            "finished": device.done and not device.runner.stopped, "steps": steps,
            "sim_s": result.duration_s, "wall_s": result.wall_s}


def run_numbered(index: int) -> dict:
    """Instruction `index` (1-based) run and judged, from the number alone (what `--jobs` processes
    and Ray workers run; g1_control/fanout.py)."""
    row = run_instruction(INSTRUCTIONS[index - 1])
    row["index"] = index
    return row


def ground_truth(row: dict) -> dict:
    """A row without its timings (parse CPU, wall time): what a run elsewhere reproduces."""
    return {k: v for k, v in row.items() if k not in ("parse_cpu_ms", "wall_s")}


def main(args) -> int:
    from g1_control.fanout import describe, fan_out

    only = {int(x) for x in args.only.split(",")} if getattr(args, "only", None) else None
    chosen = [i for i in range(1, len(INSTRUCTIONS) + 1) if not only or i in only]
    jobs, ray = int(getattr(args, "jobs", 1) or 1), getattr(args, "ray", None)
    print(f"g1 bench program: {len(chosen)} instructions, {describe(jobs, ray)}; every step judged from ground truth")
    started = time.perf_counter()
    rows = []
    for row in fan_out(run_numbered, chosen, jobs=jobs, ray=ray):
        i, text = row["index"], row["instruction"]
        rows.append(row)
        met = sum(s.get("verdict", {}).get("ok", False) for s in row["steps"])
        print(f"\n[{i}] {text}\n    {len(row['steps'])} steps ran of {row['primitives']}, {met} met by ground truth; "
              f"{'FELL' if row['fell'] else 'no fall'}; {row['sim_s']:.1f} s sim in {row['wall_s']:.1f} s wall")
        for s in row["steps"]:
            v = s.get("verdict", {})
            print(f"    {s['label']:>6}. {s['description'][:44]:<44} {s['status']:<9} "
                  f"{v.get('text', '')[:60]:<60} {'OK' if v.get('ok') else 'MISSED'}")
    sweep_s = time.perf_counter() - started
    by_kind: Counter = Counter()
    met_kind: Counter = Counter()
    for row in rows:
        for s in row["steps"]:
            by_kind[s["kind"]] += 1
            met_kind[s["kind"]] += bool(s.get("verdict", {}).get("ok"))
    steps = sum(by_kind.values())
    met = sum(met_kind.values())
    planned = sum(r["primitives"] for r in rows)
    falls = sum(r["fell"] for r in rows)
    print(f"\n{len(rows)} instructions, {planned} steps planned, {steps} ran, {met} met by ground truth "
          f"({100 * met / max(1, steps):.1f} %); falls: {falls}; unfinished programs: "
          f"{sum(not r['finished'] for r in rows)}")
    print(f"{len(rows)} instructions in {sweep_s:.1f} s wall, {describe(jobs, ray)}")
    print("per kind: " + ", ".join(f"{k} {met_kind[k]}/{n}" for k, n in sorted(by_kind.items())))
    walks = [s["verdict"]["values"]["error_rel"] for r in rows for s in r["steps"]
             if "error_rel" in s.get("verdict", {}).get("values", {})]
    turns = [s["verdict"]["values"]["error_rad"] for r in rows for s in r["steps"]
             if s["kind"] == "turn" and "error_rad" in s.get("verdict", {}).get("values", {})]
    if walks:
        print(f"walk distance error: mean |e| {100 * sum(map(abs, walks)) / len(walks):.1f} %, max "
              f"{100 * max(map(abs, walks)):.1f} % over {len(walks)} walks")
    if turns:
        import math

        print(f"turn error: mean |e| {math.degrees(sum(map(abs, turns)) / len(turns)):.1f} deg, max "
              f"{math.degrees(max(map(abs, turns))):.1f} deg over {len(turns)} turns")
    if getattr(args, "json", None):
        Path(args.json).write_text(json.dumps({"rows": rows, "steps": steps, "met": met, "falls": falls,
                                               "run": {"jobs": jobs, "ray": ray, "wall_s": sweep_s}},
                                              indent=2, default=float) + "\n")
    return 0 if falls == 0 and met == steps == planned else 1
