"""The soak: sim2sim for a chosen duration with random operator input on the emulated Unitree remote.

    g1 soak --minutes 30                 # g1 sim-robot (MuJoCo, gantry lowered on the policy) + g1 deploy
    g1 soak --minutes 2 --seed 3 --json soak.json

Both programs run exactly as an operator runs them (separate processes, DDS on lo, domain 1, an own
partition). The soak presses start and A on the emulated remote, then moves its sticks to a new
random setting every 2-6 s (one in five: both sticks released, standing), and at the end releases
them and presses B. It reports:

- trips: the deploy's safety events that damped, and how the deploy ended (a planned stop is not one);
- deadline misses of the deploy's loop: all of them, those later than a whole tick period ("over
  budget": the next tick's deadline passed too), and the worst lateness;
- memory: the deploy's and the emulator's resident size once control ran a minute, and at the end;
- the LowCmd_ stream as the robot took it: period p50/p99/p99.9/max over the whole run;
- the walk: the deploy's estimated mean velocity and the emulator's ground-truth pelvis height
  (a fall would end the run in a tilt trip).
"""

from __future__ import annotations

import argparse
import json
import os
import queue
import re
import subprocess
import sys
import threading
import time
import uuid
from pathlib import Path

import numpy as np
import yaml

from g1_control.tools.measure_sim2sim import g1_subprocess

_ROOT = Path(__file__).resolve().parents[2]
STICKS = {"ly": (-0.3, 0.7), "lx": (-0.3, 0.3), "rx": (-0.5, 0.5)}
"""Random stick ranges (the remote's own scale, [-1, 1]): forward, sideways, turning."""


class G1Process:
    """A `g1 ...` subprocess (this checkout first on PYTHONPATH) whose stdout lines are read on a
    thread, so waits can time out; stderr is drained too (a full pipe would block the process). It runs
    in the caller's working directory (where a deploy's run folder goes, as for `g1 deploy` itself)."""

    def __init__(self, *args: str, stdin: bool = False):
        self.proc = g1_subprocess(*args, stdin=subprocess.PIPE if stdin else subprocess.DEVNULL,
                                  stdout=subprocess.PIPE, stderr=subprocess.PIPE)
        stdout, stderr = self.proc.stdout, self.proc.stderr
        assert stdout is not None and stderr is not None  # both are pipes
        self.lines: queue.Queue[str] = queue.Queue()
        self.seen: list[str] = []
        self.errors: list[str] = []
        threading.Thread(target=self._pump, args=(stdout,), daemon=True).start()
        threading.Thread(target=lambda: self.errors.extend(stderr), daemon=True).start()

    def _pump(self, stdout) -> None:
        for line in stdout:
            self.lines.put(line.rstrip("\n"))

    @property
    def stderr(self) -> str:
        return "".join(self.errors)

    def wait_for(self, pattern: str, timeout_s: float) -> str:
        deadline = time.monotonic() + timeout_s
        while time.monotonic() < deadline:
            try:
                line = self.lines.get(timeout=0.1)
            except queue.Empty:
                if self.proc.poll() is not None and self.lines.empty():
                    break
                continue
            self.seen.append(line)
            if re.search(pattern, line):
                return line
        raise AssertionError(f"no line matching {pattern!r} within {timeout_s} s; got:\n" + "\n".join(self.seen)
                             + "\nstderr:\n" + self.stderr)

    def ask(self, line: str) -> dict:
        """One line to stdin (`g1 sim-robot --control-stdin`), its JSON reply."""
        stdin = self.proc.stdin
        assert stdin is not None, "started with stdin=True"
        stdin.write(line + "\n")
        stdin.flush()
        return json.loads(self.wait_for(r"^\{", 10))

    def rss_mb(self) -> float:
        try:
            text = Path(f"/proc/{self.proc.pid}/status").read_text()
        except OSError:
            return float("nan")
        found = re.search(r"VmRSS:\s+(\d+) kB", text)
        return int(found.group(1)) / 1024 if found else float("nan")

    def kill(self) -> None:
        if self.proc.poll() is None:
            self.proc.kill()
            self.proc.wait(timeout=10)


def soak_launch(folder: Path) -> Path:
    """launch/sim2sim.yaml driven by the Unitree remote, with no end of its own (the soak presses B)."""
    data = yaml.safe_load((_ROOT / "launch" / "sim2sim.yaml").read_text())
    data.update(name="soak", duration_s=None)
    data["input"] = {"type": "unitree_remote", "device": {"stale_after_s": 0.5}}
    path = folder / "soak.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


START_AFTER_LIMP_S = 2.0
"""Seconds of zero torque before the soak presses start."""


def run_soak(minutes: float, seed: int = 0, out: Path | None = None, progress=print) -> dict:
    rng = np.random.default_rng(seed)
    partition = f"g1soak-{os.getpid()}-{uuid.uuid4().hex[:6]}"
    out = Path(out or "runs")
    out.mkdir(parents=True, exist_ok=True)
    work = out / f"soak-{time.strftime('%Y%m%d-%H%M%S')}"
    work.mkdir()
    robot = G1Process("sim-robot", "--partition", partition, "--control-stdin", "--lower-gantry-on-policy", stdin=True)
    host = None
    memory: list[dict] = []
    changes = 0
    try:
        robot.wait_for("^ready$", 120)
        host = G1Process("deploy", str(soak_launch(work)), "--partition", partition, "--json",
                         str(work / "deploy.json"), "--out", str(work))
        host.wait_for(r"zero torque: the robot is limp", 180)
        # as an operator does: start once the limp robot has hung in its gantry for a moment
        time.sleep(START_AFTER_LIMP_S)
        robot.ask("press start")
        host.wait_for(r"ramp -> hold", 30)
        time.sleep(0.6)  # deploy.min_hold_s
        robot.ask("press A")
        host.wait_for(r"hold -> control", 30)
        t0 = time.monotonic()
        end = t0 + minutes * 60.0
        next_change = t0
        next_sample = t0
        while time.monotonic() < end and host.proc.poll() is None:
            now = time.monotonic()
            if now >= next_change:
                stand = rng.random() < 0.2
                for name, (lo, hi) in STICKS.items():
                    robot.ask(f"stick {name} {0.0 if stand else float(rng.uniform(lo, hi)):.3f}")
                changes += 1
                next_change = now + float(rng.uniform(2.0, 6.0))
            if now >= next_sample:
                memory.append({"t_s": round(now - t0, 1), "deploy_rss_mb": host.rss_mb(),
                               "emulator_rss_mb": robot.rss_mb()})
                next_sample = now + 10.0
                if len(memory) % 6 == 1:
                    progress(f"[{(now - t0) / 60:5.1f} min] deploy {memory[-1]['deploy_rss_mb']:.1f} MB, "
                             f"emulator {memory[-1]['emulator_rss_mb']:.1f} MB, {changes} stick settings")
            time.sleep(0.05)
        control_s = time.monotonic() - t0
        still_running = host.proc.poll() is None
        memory.append({"t_s": round(control_s, 1), "deploy_rss_mb": host.rss_mb(), "emulator_rss_mb": robot.rss_mb()})
        for name in STICKS:
            robot.ask(f"stick {name} 0.0")
        if still_running:
            time.sleep(2.0)
            robot.ask("press B")
        code = host.proc.wait(timeout=120)
        wire = robot.ask("report")
    finally:
        if host is not None:
            host.kill()
        try:
            robot.ask("quit")
        except (OSError, AssertionError, ValueError):
            pass
        robot.kill()
    report = json.loads((work / "deploy.json").read_text())
    trips = [e for e in report["safety_events"] if e["trips"] and not e.get("planned")]
    first_minute = next((m for m in memory if m["t_s"] >= 60.0), memory[0])
    summary = {
        "minutes": minutes, "seed": seed, "control_s": control_s, "stick_settings": changes,
        "exit_code": code, "end_reason": report["end_reason"], "fault": report["fault"],
        "ended_by_operator_stop": report["end_reason"] == "operator stop",
        "trips": trips, "safety_events": len(report["safety_events"]),
        "deadline_misses": report["loop"]["deadline_misses"],
        "deadline_misses_over_budget": report["loop"].get("misses_over_period"),
        "worst_lateness_ms": report["loop"].get("lateness_max_ms"), "ticks": report["loop"]["ticks"],
        "memory": {"deploy_rss_mb_at_1min": first_minute["deploy_rss_mb"], "deploy_rss_mb_end": memory[-1]["deploy_rss_mb"],
                   "emulator_rss_mb_at_1min": first_minute["emulator_rss_mb"],
                   "emulator_rss_mb_end": memory[-1]["emulator_rss_mb"], "samples": memory},
        "lowcmd": {k: v for k, v in wire.items() if k.startswith("lowcmd_")},
        "wire": {k: wire.get(k) for k in ("bad_crc", "wrong_mode_machine", "commands_applied", "damping_commands",
                                          "last_command_is_damping")},
        "pelvis_height_at_stop_m": (wire.get("first_damping_base_pos_w_m") or [None] * 3)[2],
        "velocity_est_mean": report["control"].get("velocity_est_mean"),
        "run_dir": report.get("run_dir"), "work_dir": str(work),
    }
    m = summary["memory"]
    summary["memory"]["deploy_growth_mb"] = m["deploy_rss_mb_end"] - m["deploy_rss_mb_at_1min"]
    summary["memory"]["emulator_growth_mb"] = m["emulator_rss_mb_end"] - m["emulator_rss_mb_at_1min"]
    (work / "soak.json").write_text(json.dumps(summary, indent=2, default=float))
    return summary


def format_summary(s: dict) -> str:
    m, w = s["memory"], s["lowcmd"]
    lines = [
        f"soak: {s['control_s'] / 60:.1f} min of control, {s['stick_settings']} random stick settings (seed {s['seed']})",
        f"ended: {s['end_reason']} (exit {s['exit_code']}){'  FAULT' if s['fault'] else ''}",
        f"trips: {len(s['trips'])}" + "".join(f"\n  {t['kind']}: {t['detail']}" for t in s["trips"]),
        f"deadline misses: {s['deadline_misses']} of {s['ticks']} ticks; over budget (> one tick late): "
        f"{s['deadline_misses_over_budget']}; worst {s['worst_lateness_ms']:.1f} ms late",
        f"memory (RSS): deploy {m['deploy_rss_mb_at_1min']:.1f} MB at 1 min -> {m['deploy_rss_mb_end']:.1f} MB at the "
        f"end ({m['deploy_growth_mb']:+.1f} MB); emulator {m['emulator_rss_mb_at_1min']:.1f} -> "
        f"{m['emulator_rss_mb_end']:.1f} MB ({m['emulator_growth_mb']:+.1f} MB)",
        f"lowcmd at the robot: {w.get('lowcmd_periods', 0)} periods, p50 {w.get('lowcmd_period_all_p50_ms', 0):.2f} ms, "
        f"p99 {w.get('lowcmd_period_all_p99_ms', 0):.2f} ms, p99.9 {w.get('lowcmd_period_all_p999_ms', 0):.2f} ms, "
        f"max {w.get('lowcmd_period_all_max_ms', 0):.1f} ms ({w.get('lowcmd_periods_over_10ms', 0)} over 10 ms)",
        f"wire: {s['wire']}",
        f"pelvis height when the operator stopped: {s['pelvis_height_at_stop_m']} m (standing ~0.75, fallen < 0.4); "
        f"estimated mean velocity {s['velocity_est_mean']}",
        f"files: {s['work_dir']}",
    ]
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    add_arguments(parser)
    return run_from_args(parser.parse_args(argv))


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--minutes", type=float, default=30.0, help="control time (default 30)")
    parser.add_argument("--seed", type=int, default=0, help="seed of the random stick input")
    parser.add_argument("--out", type=Path, default=Path("runs"), help="where the soak folder goes (default runs/)")
    parser.add_argument("--json", type=Path, help="also write the summary here")


def run_from_args(args) -> int:
    summary = run_soak(args.minutes, args.seed, args.out)
    print(format_summary(summary))
    if args.json:
        args.json.write_text(json.dumps(summary, indent=2, default=float))
    ok = not summary["trips"] and summary["ended_by_operator_stop"] and summary["deadline_misses_over_budget"] == 0
    return 0 if ok else 3


if __name__ == "__main__":
    sys.exit(main())
