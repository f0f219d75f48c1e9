"""Measure sim2sim: `g1 sim-robot --lower-gantry-on-policy` and `g1 deploy launch/sim2sim.yaml --yes`
as two processes on lo/domain 1 (a private partition), the emulator sampled for ground truth.

    python -m g1_control.tools.measure_sim2sim                 # prints one JSON object
    python -m g1_control.tools.measure_sim2sim --generator     # launch/sim2sim_generator.yaml, styles on the d-pad

Reports the LowCmd_ stream as the robot took it off the wire (rate, period p50/p99/max), the
walking velocity from the simulator's base position over the steady part of the forward segment
(from 3 s after control began to its end), the host's own estimate, and the state sequence.

With --generator: the generator -> IK -> policy chain over DDS; once control began, the emulated
remote walks the robot (left stick) and presses d-pad right every STYLE_S seconds to step through the
launch file's styles. Reports, per style, the upper-body joints the emulator reported vs the plan the
host tracked (RMS), and the chains of the robot loop and of the preflight's dry run.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time
import uuid
from pathlib import Path

_ROOT = Path(__file__).resolve().parents[2]


def g1_subprocess(*args: str, **kwargs) -> subprocess.Popen:
    """`python -m g1_control.cli.main *args` with this checkout first on PYTHONPATH, in the caller's
    working directory (text mode, line-buffered; kwargs go to Popen)."""
    env = {**os.environ, "PYTHONPATH": str(_ROOT) + os.pathsep + os.environ.get("PYTHONPATH", "")}
    return subprocess.Popen([sys.executable, "-m", "g1_control.cli.main", *args], env=env, text=True,
                            bufsize=1, **kwargs)


STYLE_S = 3.5
"""Seconds per style in --generator mode."""


def measure(launch: str = "launch/sim2sim.yaml", generator: bool = False) -> dict:
    if not Path(launch).is_file() and (_ROOT / launch).is_file():  # the checkout's launch files from anywhere
        launch = str(_ROOT / launch)
    if not Path(launch).is_file():
        raise FileNotFoundError(f"{launch}: no such launch file")
    partition = f"g1measure-{os.getpid()}-{uuid.uuid4().hex[:6]}"
    robot = g1_subprocess("sim-robot", "--lower-gantry-on-policy", "--partition", partition, "--control-stdin",
                stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL)
    to_robot, from_robot = robot.stdin, robot.stdout
    assert to_robot is not None and from_robot is not None  # both opened as pipes just above
    host = None

    def ask(word: str) -> dict:
        to_robot.write(word + "\n")
        to_robot.flush()
        return json.loads(from_robot.readline())

    try:
        if from_robot.readline().strip() != "ready":
            raise RuntimeError("the emulator did not start")
        with tempfile.TemporaryDirectory() as tmp:
            report_path = Path(tmp) / "deploy.json"
            host = g1_subprocess("deploy", launch, "--yes", "--partition", partition, "--json", str(report_path),
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            samples = []
            next_style_s, walking = None, False
            while host.poll() is None:
                r = ask("report")
                if r.get("gantry_lowered_at_s") == r.get("gantry_lowered_at_s"):  # not NaN: control began
                    now = time.monotonic()
                    samples.append((now, r["base_pos_w_m"], r["gantry_lowered_at_s"]))
                    if generator:
                        if next_style_s is None:
                            next_style_s = now + STYLE_S
                        if not walking and now > r["gantry_lowered_at_s"] + 2.0:
                            ask("stick ly 0.5")
                            walking = True
                        if now >= next_style_s:
                            ask("press right")
                            next_style_s = now + STYLE_S
                time.sleep(0.25)
            if not report_path.is_file():
                raise RuntimeError(f"g1 deploy {launch} ended (exit {host.returncode}) without a report; run it "
                                   "by hand to see why")
            report = json.loads(report_path.read_text())
        wire = ask("report")
        end = wire["first_damping_time_s"]
        steady = [(t, p) for t, p, t0 in samples if t0 + 3.0 <= t <= end]
        (t1, p1), (t2, p2) = steady[0], steady[-1]
        return {
            "sequence": report["sequence"], "end_reason": report["end_reason"], "host_exit": host.returncode,
            "lowcmd_wire": {k: wire[k] for k in wire if k.startswith("lowcmd_")},
            "lowcmd_sender": {"rate_hz": report["link"]["command_rate_hz"],
                              "period_p99_ms": report["link"]["command_period_p99_s"] * 1e3},
            "walk_vx_true_mps": (p2[0] - p1[0]) / (t2 - t1), "walk_vy_true_mps": (p2[1] - p1[1]) / (t2 - t1),
            "walk_window_s": t2 - t1, "walk_vx_host_estimate_mps": report["control"]["velocity_est_mean"][0],
            "pelvis_height_at_damping_m": wire["first_damping_base_pos_w_m"][2],
            "deadline_misses": report["loop"]["deadline_misses"],
            "upper_body_vs_plan": report["control"].get("upper_body_vs_plan"),
            "chain": report.get("chain"), "dry_run_chain": report.get("dry_run_chain"),
        }
    finally:
        if host is not None and host.poll() is None:
            host.kill()
        try:
            to_robot.write("quit\n")
            to_robot.flush()
            robot.wait(timeout=10)
        except (OSError, subprocess.TimeoutExpired):
            robot.kill()


def main(argv: list[str] | None = None) -> int:
    import argparse

    parser = argparse.ArgumentParser(prog="python -m g1_control.tools.measure_sim2sim",
                                     description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("launch", nargs="?", help="a sim2sim launch file (default launch/sim2sim.yaml, or "
                        "launch/sim2sim_generator.yaml with --generator)")
    parser.add_argument("--generator", action="store_true", help="step through the styles with the d-pad and "
                        "report the upper body vs the plan per style")
    args = parser.parse_args(argv)
    default = "launch/sim2sim_generator.yaml" if args.generator else "launch/sim2sim.yaml"
    print(json.dumps(measure(args.launch or default, generator=args.generator), indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
