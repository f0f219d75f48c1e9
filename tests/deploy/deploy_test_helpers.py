"""Shared pieces of the deploy tests: launch files derived from launch/sim2sim.yaml, DDS
partitions (concurrent runs on this host never see each other), emulated robots on lo/domain 1."""

from __future__ import annotations

import os
import re
import uuid
import warnings
from dataclasses import dataclass
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parents[2]
SIM2SIM = ROOT / "launch" / "sim2sim.yaml"
SIM2SIM_GENERATOR = ROOT / "launch" / "sim2sim_generator.yaml"


def new_partition() -> str:
    return f"g1deploy-{os.getpid()}-{uuid.uuid4().hex[:8]}"


def write_launch(folder: Path, changes: dict | None = None, name: str = "launch.yaml", base: Path = SIM2SIM) -> Path:
    """launch/sim2sim.yaml with `changes` merged in (nested dicts merge; None deletes a key)."""
    data = yaml.safe_load(base.read_text())

    def merge(target: dict, update: dict) -> None:
        for key, value in update.items():
            if value is None:
                target.pop(key, None)
            elif isinstance(value, dict) and isinstance(target.get(key), dict):
                merge(target[key], value)
            else:
                target[key] = value

    merge(data, changes or {})
    path = folder / name
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def preflight_only(path: Path, partition: str, **options):
    """g1 deploy --preflight-only in this process: (report, PreflightRefused or None, printed text)."""
    from g1_control.deploy.preflight import PreflightRefused
    from g1_control.deploy.session import DeployOptions, deploy

    lines: list[str] = []
    try:
        report = deploy(path, DeployOptions(preflight_only=True, partition=partition, **options), say=lines.append)
        return report, None, "\n".join(lines)
    except PreflightRefused as exc:
        return exc.report, exc, "\n".join(lines)


FAST = {"deploy": {"state_window_s": 0.3, "input_check_s": 0.1}, "backend": {"connect_timeout_s": 2.0}}
"""Shorter listening windows for tests that only need the checklist's verdict."""


class SecondPublisher:
    """Another writer on rt/lowstate in the same domain and partition (lo, domain 1): valid CRCs, as a
    second robot or a spoofing program would send. `source()` gives the RobotState to report. The
    writer exists (and DDS discovery sees it) from start() + delay_s on."""

    def __init__(self, partition: str, source, mode_machine: int = 5, rate_hz: float = 500.0):
        import threading

        self.partition, self.link = partition, None
        self.source, self.mode_machine, self.period_s = source, mode_machine, 1.0 / rate_hz
        self.sent = 0
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None

    def start(self, seconds: float, delay_s: float = 0.0) -> SecondPublisher:
        import threading

        self._thread = threading.Thread(target=self._run, args=(seconds, delay_s), daemon=True)
        self._thread.start()
        return self

    def _run(self, seconds: float, delay_s: float) -> None:
        import time

        from g1_control.hardware.links.dds import DdsLink
        from g1_control.hardware.unitree.conversions import robot_state_to_lowstate

        if self._stop.wait(delay_s):
            return
        self.link = DdsLink("robot", "lo", 1, partition=self.partition)
        end = time.monotonic() + seconds
        tick = 10_000_000
        while not self._stop.is_set() and time.monotonic() < end:
            state = self.source()
            state.mode_machine, state.tick = self.mode_machine, tick
            self.link.send(self.link.encode(robot_state_to_lowstate(state)))
            self.sent += 1
            tick += 1
            self._stop.wait(self.period_s)

    def join(self) -> None:
        if self._thread is not None:
            self._thread.join()

    def close(self) -> None:
        self._stop.set()
        self.join()
        if self.link is not None:
            self.link.close()


@dataclass
class LinkStats:
    """A robot link's transport counters (LinkBackend.stats()), for stand-in backends of preflight tests."""

    states_received: int = 0
    bad_crc: int = 0
    malformed: int = 0
    bad_frames: int = 0


def standing_state(**changes):
    """A healthy 29-DoF robot's RobotState at the default pose, 40 °C, with `changes` set on it."""
    import numpy as np

    from g1_control.robot import g1
    from g1_control.types import RobotState

    state = RobotState(q_rad=g1.DEFAULT_Q_RAD.copy(), motor_temperature_c=np.full(29, 40.0), mode_machine=5)
    for k, v in changes.items():
        setattr(state, k, v)
    return state


HOST_TIMING_TRIP = re.compile(r"-> damping: (deadline_overruns|stale_state): ")
"""A deploy that damped because this host could not keep its loop's rate or deliver states in time."""
STALLED_LOOP = re.compile(r"(?:^|\s)loop: .*; ([1-9][0-9]*) ticks skipped after stalls\)")
"""The deploy's loop line when this host stalled it for whole periods (the scheduler skipped ticks)."""
TIMING_ATTEMPTS = 3


def _host_timing(failure: str) -> str | None:
    """Why a failed deploy is this host's timing (the lines that say so), or None."""
    lines = failure.splitlines()
    trip = next((t.strip() for t in lines if HOST_TIMING_TRIP.search(t)), None)
    if trip is not None:
        return trip
    damped = next((t.strip() for t in lines if re.search(r"control -> damping: (?!control time over)", t)), None)
    stalled = next((t.strip() for t in lines if STALLED_LOOP.search(t.strip())), None)
    return f"{damped} after a stalled loop ({stalled})" if damped and stalled else None


def deploy_to_the_end(partition: str, launch: Path, json_path: Path, out: Path, emulator_flags=(), deploy_flags=(),
                      waits=((r"control -> damping: control time over", 240), (r"^loop: ", 30))):
    """`g1 sim-robot` (flags) and `g1 deploy LAUNCH --yes` as two processes, the deploy waited through `waits`
    (pattern, seconds) to its exit; (the deploy process, the emulator's wire report). Both are ended either way.

    The controller and the emulated robot share this host's cores (two, shared with other work). A deploy that
    damps on this host's timing is run again, in a new partition, up to TIMING_ATTEMPTS runs in all, each
    retry a warning in the test report naming why: a timing trip (missed deadlines, a stale state), or any
    trip in control after the host stalled the loop for whole periods (its ticks skipped: a walk that fell
    after a 24 ms stall). Any other failure fails at once; a deploy that fails on timing every time fails."""
    for attempt in range(1, TIMING_ATTEMPTS + 1):
        name = partition if attempt == 1 else f"{partition}-r{attempt}"
        try:
            return _deploy_once(name, launch, json_path, out, emulator_flags, deploy_flags, waits)
        except AssertionError as exc:
            why = _host_timing(str(exc))
            if why is None or attempt == TIMING_ATTEMPTS:
                raise
            warnings.warn(f"{launch.name}: the deploy failed on this host's timing (attempt {attempt} of "
                          f"{TIMING_ATTEMPTS}), run again: {why}", stacklevel=2)
    raise AssertionError("unreachable")


def _deploy_once(partition, launch, json_path, out, emulator_flags, deploy_flags, waits):
    from test_deploy_sim2sim import Emulator

    from g1_control.tools.soak import G1Process

    robot = Emulator(partition, *emulator_flags)
    host = None
    try:
        host = G1Process("deploy", str(launch), "--yes", "--partition", partition, "--json", str(json_path),
                         "--out", str(out), *deploy_flags)
        for pattern, seconds in waits:
            host.wait_for(pattern, seconds)
        assert host.proc.wait(timeout=30) == 0, host.stderr
        wire = robot.ask("report")
    finally:
        if host is not None:
            host.kill()
        robot.close()
    return host, wire
