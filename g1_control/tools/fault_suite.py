"""Fault-injection suite over real DDS on loopback: the emulator (`g1 sim-robot --physics mock`) in
one process, a guarded 50 Hz hold controller in another, one fault at a time; for each, when the
safety layer tripped and when the emulator first received a damping frame.

    python -m g1_control.tools.fault_suite            # prints the fault -> detection table

Robot-side faults are injected in the emulator, host-side ones (NaN policy output, lost joystick,
deadline overruns, SIGINT, SIGTERM) in the host. Times are CLOCK_MONOTONIC, shared by all
processes on the host, so they compare across processes.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import signal
import subprocess
import sys
import threading
import time
import uuid
from collections import deque
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from g1_control.errors import G1ControlError
from g1_control.robot import g1
from g1_control.types import Command, MotorCommand

TICK_S = 0.02  # 50 Hz controller
ROBOT_FAULTS = ("state_stops", "state_frozen", "crc_corrupted", "tilt", "overspeed", "over_temperature")
HOST_FAULTS = ("nan_policy_output", "joystick_lost", "deadline_overruns")
SIGNAL_FAULTS = ("SIGINT", "SIGTERM")
ALL_FAULTS = ROBOT_FAULTS + HOST_FAULTS + SIGNAL_FAULTS
_ROOT = Path(__file__).resolve().parents[2]


@dataclass
class FaultResult:
    fault: str
    tripped_as: str
    detect_ms: float
    """Fault injected -> safety layer tripped."""
    to_wire_ms: float
    """Tripped -> first damping frame received by the robot (emulator)."""
    total_ms: float
    detail: str


def hold_command() -> MotorCommand:
    return MotorCommand(q_rad=g1.DEFAULT_Q_RAD.copy(), kp=g1.KP_DEFAULT.copy(), kd=g1.KD_DEFAULT.copy())


class HoldController:
    """The host side: hold the default pose at 50 Hz through a GuardedBackend, with fault switches."""

    def __init__(self, robot):
        self.robot = robot
        self.nan_output = False
        self.joystick_lost = False
        self.overrun_s = 0.0
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name="hold-controller", daemon=True)

    def start(self) -> HoldController:
        self._thread.start()
        return self

    def stop(self) -> None:
        self._stop.set()
        self._thread.join(timeout=2.0)

    def _run(self) -> None:
        safety = self.robot.safety
        next_t = time.monotonic()
        while not self._stop.is_set():
            start = time.monotonic()
            safety.vet_input(None if self.joystick_lost else Command(), start)
            command = hold_command()
            if self.nan_output:
                command.q_rad[3] = math.nan
            self.robot.write_command(command)
            if self.overrun_s:
                time.sleep(self.overrun_s)  # a tick whose work overruns its deadline
            next_t += TICK_S
            overran = time.monotonic() > next_t
            self.robot.report_deadline(overran, detail=f"tick took {(time.monotonic() - start) * 1000:.0f} ms")
            if overran:
                next_t = time.monotonic()
            self._stop.wait(max(0.0, next_t - time.monotonic()))


def _open_robot(partition: str):
    from g1_control.hardware.dds_backend import UnitreeDDSBackend
    from g1_control.safety import GuardedBackend, SafetyConfig

    backend = UnitreeDDSBackend("lo", 1, partition=partition, connect_timeout_s=5.0, motion_service_timeout_s=5.0)
    robot = GuardedBackend(backend, SafetyConfig())
    robot.reset()
    return robot


class _Emulator:
    def __init__(self, partition: str):
        env = {**os.environ, "PYTHONPATH": str(_ROOT) + os.pathsep + os.environ.get("PYTHONPATH", "")}
        self.proc = subprocess.Popen(
            [sys.executable, "-m", "g1_control.cli.main", "sim-robot", "--physics", "mock", "--partition", partition,
             "--control-stdin"], cwd=_ROOT, env=env, stdin=subprocess.PIPE, stdout=subprocess.PIPE,
            stderr=subprocess.PIPE, text=True, bufsize=1)
        stdin, stdout, stderr = self.proc.stdin, self.proc.stdout, self.proc.stderr
        assert stdin is not None and stdout is not None and stderr is not None  # all three are pipes
        self._stdin, self._stdout = stdin, stdout
        # stderr is drained on a thread: a full pipe would block the emulator on its next log line.
        self.errors: deque[str] = deque(maxlen=50)
        threading.Thread(target=lambda: self.errors.extend(stderr), daemon=True).start()
        if stdout.readline().strip() != "ready":
            self.proc.wait(timeout=10)
            raise RuntimeError(f"emulator did not start: {''.join(self.errors)}")

    @property
    def alive(self) -> bool:
        return self.proc.poll() is None

    def ask(self, word: str) -> dict:
        try:
            self._stdin.write(word + "\n")
            self._stdin.flush()
            line = self._stdout.readline()
        except OSError as exc:
            line = ""
            self.errors.append(str(exc))
        if not line:
            raise RuntimeError(f"the emulator exited (status {self.proc.poll()}): {''.join(self.errors)[-600:]}")
        return json.loads(line)

    def close(self) -> None:
        try:
            self._stdin.write("quit\n")
            self._stdin.flush()
            self.proc.wait(timeout=10)
        except (OSError, subprocess.TimeoutExpired):
            self.proc.kill()


def _wait_for_damping(emulator: _Emulator, timeout_s: float = 3.0) -> float:
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        t = emulator.ask("report")["first_damping_time_s"]
        if not math.isnan(t):
            return t
        time.sleep(0.02)
    return math.nan


def _result(fault: str, t_inject: float, robot, t_wire: float) -> FaultResult:
    event = robot.safety.trip_event
    t_trip = event.t_s if event else math.nan
    return FaultResult(fault, event.kind.value if event else "(none)", (t_trip - t_inject) * 1000,
                       (t_wire - t_trip) * 1000, (t_wire - t_inject) * 1000, event.detail if event else "")


def run_in_process_fault(fault: str, emulator: _Emulator, robot) -> FaultResult:
    emulator.ask("clear")
    controller = HoldController(robot).start()
    try:
        time.sleep(0.3)  # healthy running first: nothing may trip
        if robot.safety.tripped:
            raise RuntimeError(f"safety tripped before fault '{fault}' was injected: {robot.safety.trip_event}")
        if fault in ROBOT_FAULTS:
            t_inject = emulator.ask(fault)["t_s"]
        else:
            t_inject = time.monotonic()
            if fault == "nan_policy_output":
                controller.nan_output = True
            elif fault == "joystick_lost":
                controller.joystick_lost = True
            elif fault == "deadline_overruns":
                controller.overrun_s = 0.03
        t_wire = _wait_for_damping(emulator)
    finally:
        controller.stop()
    return _result(fault, t_inject, robot, t_wire)


def run_signal_fault(sig: str, emulator: _Emulator, partition: str) -> FaultResult:
    emulator.ask("clear")
    env = {**os.environ, "PYTHONPATH": str(_ROOT) + os.pathsep + os.environ.get("PYTHONPATH", "")}
    host = subprocess.Popen([sys.executable, "-m", "g1_control.tools.fault_suite", "--host", partition],
                            cwd=_ROOT, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    assert host.stdout is not None and host.stderr is not None  # both opened as pipes just above
    try:
        if host.stdout.readline().strip() != "holding":
            raise RuntimeError(f"host did not start: {host.stderr.read()}")
        time.sleep(0.3)
        t_inject = time.monotonic()
        host.send_signal(getattr(signal, sig))
        t_wire = _wait_for_damping(emulator)
        out, err = host.communicate(timeout=10)
    finally:
        if host.poll() is None:
            host.kill()
    trip = json.loads(out.strip().splitlines()[-1]) if out.strip() else {}
    t_trip = trip.get("t_s", math.nan)
    return FaultResult(sig, trip.get("kind", "(none)"), (t_trip - t_inject) * 1000, (t_wire - t_trip) * 1000,
                       (t_wire - t_inject) * 1000, trip.get("detail", err.strip()[-200:]))


HOST_RT_PRIORITY = 20
"""The host controller's real-time priority during the suite (as g1 deploy's deploy.realtime_priority)."""


def run_suite(faults=ALL_FAULTS, progress: bool = True) -> list[FaultResult]:
    from g1_control.loop.priority import realtime

    normal, _ = realtime(HOST_RT_PRIORITY)
    try:
        return _run_suite(faults, progress)
    finally:
        normal.restore()


SETUP_ATTEMPTS = 3
"""A trial whose healthy phase trips before its fault is injected (a stall on a loaded host) is tried
again with a fresh robot this many times in all; then it is recorded as failed and the suite goes on."""


def _run_suite(faults, progress: bool) -> list[FaultResult]:
    from tqdm import tqdm

    partition = f"g1faults-{os.getpid()}-{uuid.uuid4().hex[:6]}"
    emulator = _Emulator(partition)
    results = []
    try:
        for fault in tqdm(faults, desc="fault injection", unit="fault", disable=not progress):
            if not emulator.alive:  # a dead robot must not fail every later trial too
                emulator = _Emulator(partition)
            results.append(_trial(fault, emulator, partition))
    finally:
        emulator.close()
    return results


def _trial(fault: str, emulator: _Emulator, partition: str) -> FaultResult:
    """One fault, its setup retried (SETUP_ATTEMPTS); a setup that keeps failing is a failed result."""
    problems = []
    for _ in range(SETUP_ATTEMPTS):
        try:
            if fault in SIGNAL_FAULTS:
                return run_signal_fault(fault, emulator, partition)
            emulator.ask("clear")  # the previous trial's fault must not greet the next robot
            robot = _open_robot(partition)  # a fresh safety layer for every trial
            try:
                return run_in_process_fault(fault, emulator, robot)
            finally:
                robot.close()
        except (RuntimeError, G1ControlError, ValueError) as exc:
            problems.append(str(exc))
            if not emulator.alive:
                break
    return FaultResult(fault, "(setup failed)", math.nan, math.nan, math.nan,
                       f"{SETUP_ATTEMPTS} attempts: " + " | ".join(problems))


def format_table(results: list[FaultResult]) -> str:
    lines = [f"{'fault':20s} {'tripped as':18s} {'detect ms':>10s} {'to wire ms':>11s} {'total ms':>9s}  detail"]
    for r in results:
        lines.append(f"{r.fault:20s} {r.tripped_as:18s} {r.detect_ms:10.1f} {r.to_wire_ms:11.1f} {r.total_ms:9.1f}  "
                     f"{r.detail}")
    return "\n".join(lines)


def _host_main(partition: str) -> int:
    """Subprocess host for the signal faults: hold until a signal, then report the trip as JSON."""
    from g1_control.loop.priority import realtime
    from g1_control.safety import install_signal_damping

    realtime(HOST_RT_PRIORITY)
    robot = _open_robot(partition)
    install_signal_damping(robot)
    controller = HoldController(robot).start()
    print("holding", flush=True)
    try:
        while True:
            time.sleep(0.05)
    except KeyboardInterrupt:
        pass
    finally:
        controller.stop()
        robot.close()
    event = robot.safety.trip_event
    print(json.dumps({"kind": event.kind.value, "t_s": event.t_s, "detail": event.detail} if event else {}),
          flush=True)
    return 0


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--faults", nargs="+", choices=ALL_FAULTS, default=list(ALL_FAULTS))
    parser.add_argument("--json", help="also write the results as JSON")
    parser.add_argument("--host", metavar="PARTITION", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.host:
        return _host_main(args.host)
    results = run_suite(args.faults)
    print(format_table(results))
    if args.json:
        Path(args.json).write_text(json.dumps([asdict(r) for r in results], indent=2))
    return 0 if all(np.isfinite(r.total_ms) for r in results) else 1


if __name__ == "__main__":
    sys.exit(main())
