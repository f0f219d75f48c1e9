"""The goal planner's own process: where whole-body plans are made beside a wall-clock loop.

A plan (footsteps for a carry, a grasp's four poses, a reach) takes 0.1-3 s of CPU. Made in a
thread beside the control loop, it shares the interpreter's lock with the loop and, where the
deploy runs every thread of its process at SCHED_RR (loop/priority.py), the loop's priority too:
measured over DDS against `g1 sim-robot` on 2 cores, the loop then waited up to 100 ms (one
round-robin time slice of the planner thread) and the safety layer tripped on "10 deadline
overruns within 1.0 s" as a pick's plans started. Here the planning runs in a process of its own,
started afresh (not forked: the parent runs DDS threads) with its own PosePlanner, at ordinary
scheduling (SCHED_OTHER), so that every real-time thread (the loop, the link's writer) preempts it
at once and it never holds the loop's interpreter lock. Beside a real-time loop its session, and so
its autogroup, is its own with nice AUTOGROUP_NICE: ordinary work on a busy host (other sessions
weigh as much as ours) does not starve a plan (measured: a pick's plans took ~30 s of wall time at
nice 0 in the deploy's group on a shared 2-core host), and it stays out of the kernel's real-time
budget (sched_rt_runtime_us: 95 %), which a planner one real-time priority below the loop used up
(measured: the loop stalled 43 ms once, 2.6 s into a 3 s plan). It stops when its parent closes the
socket (or dies).

A job is a function at a module's top level (or a PosePlanner method) called as fn(poses, *args)
with picklable arguments (arrays, footsteps, configs); its result (arrays, plans) or its exception
comes back as a Future, set by a reader thread (the loop thread only sends the small request).
GoalContext.compute runs the same functions inline in lockstep.
"""

from __future__ import annotations

import contextlib
import itertools
import os
import socket
import subprocess
import sys
import threading
from collections.abc import Callable, Iterator
from concurrent.futures import Future
from multiprocessing.connection import Connection
from pathlib import Path
from typing import Any

from g1_control.errors import G1ControlError


class PlannerDied(G1ControlError):
    """The planner process ended while a plan was being made."""


def _serve(conn) -> None:
    """The planner process: (job id, fn, args) in, (job id, ok, result or exception) out, until None."""
    from g1_control.generator.goals.poses import PosePlanner

    poses = PosePlanner()
    while True:
        try:
            job = conn.recv()
        except (EOFError, OSError):  # the parent is gone
            return
        if job is None:
            return
        job_id, fn, args = job
        try:
            reply = (job_id, True, fn(poses, *args))
        except Exception as exc:  # the skill's own errors (ReachRefused, GoalFailed) go back to it
            reply = (job_id, False, exc)
        conn.send(reply)


def _pid(_poses) -> int:
    return os.getpid()


AUTOGROUP_NICE = -20
"""The planner's scheduling group's nice value beside a real-time loop (module docstring)."""


def _real_time() -> bool:
    return os.sched_getscheduler(0) in (os.SCHED_RR, os.SCHED_FIFO)


@contextlib.contextmanager
def _ordinary_scheduling() -> Iterator[None]:
    """This thread at SCHED_OTHER for the block, so that a process started in it does not inherit a
    real-time policy."""
    policy, param = os.sched_getscheduler(0), os.sched_getparam(0)
    if policy == os.SCHED_OTHER:
        yield
        return
    os.sched_setscheduler(0, os.SCHED_OTHER, os.sched_param(0))
    try:
        yield
    finally:
        with contextlib.suppress(OSError):
            os.sched_setscheduler(0, policy, param)


def _above_ordinary_work() -> None:
    """In the planner process (a session, hence a scheduling autogroup, of its own): its group's nice
    value to AUTOGROUP_NICE, where the OS allows it (root or CAP_SYS_NICE); otherwise as it is."""
    with contextlib.suppress(OSError), open("/proc/self/autogroup", "w") as group:
        group.write(str(AUTOGROUP_NICE))


class PlannerProcess:
    """One planner process (module docstring), started at once so that the first goal does not wait
    for its imports. It runs this module as a program (`python -m`), not multiprocessing's spawn,
    which would run the parent's main script again in the child."""

    def __init__(self) -> None:
        parent, child = socket.socketpair()
        package_root = str(Path(__file__).resolve().parents[3])  # the g1_control the parent runs
        env = dict(os.environ, PYTHONPATH=os.pathsep.join([package_root, *filter(None, [os.environ.get("PYTHONPATH")])]))
        argv = [sys.executable, "-m", __name__, str(child.fileno())] + (["--above-ordinary-work"] if _real_time() else [])
        with _ordinary_scheduling():
            self._process = subprocess.Popen(argv, pass_fds=[child.fileno()], env=env, stdin=subprocess.DEVNULL,
                                             start_new_session=True)
        child.close()
        self._conn = Connection(parent.detach())
        self._jobs: dict[int, Future] = {}
        self._ids = itertools.count()
        self._lock = threading.Lock()
        self._reader = threading.Thread(target=self._read, name="goal-planner-reader", daemon=True)
        self._reader.start()
        self.started: Future = self.submit(_pid)
        """The planner's process id once it is up (a job like any other)."""

    def submit(self, fn: Callable[..., Any], *args: Any) -> Future:
        """fn(poses, *args) in the planner process."""
        future: Future = Future()
        with self._lock:
            if self._process.poll() is not None:
                future.set_exception(self._died())
                return future
            job_id = next(self._ids)
            self._jobs[job_id] = future
            self._conn.send((job_id, fn, args))
        return future

    def _read(self) -> None:
        while True:
            try:
                job_id, ok, value = self._conn.recv()
            except (EOFError, OSError):
                break
            with self._lock:
                future = self._jobs.pop(job_id, None)
            if future is not None:
                (future.set_result if ok else future.set_exception)(value)
        with self._lock:  # the process is gone: nothing more will come back
            jobs, self._jobs = self._jobs, {}
        for future in jobs.values():
            future.set_exception(self._died())

    def _died(self) -> PlannerDied:
        with contextlib.suppress(subprocess.TimeoutExpired):
            self._process.wait(timeout=1.0)
        return PlannerDied(f"the goal planner process ended (exit code {self._process.returncode})")

    def close(self) -> None:
        """Stop the process (a plan in progress is abandoned)."""
        with contextlib.suppress(OSError, ValueError):
            self._conn.send(None)
        try:
            self._process.wait(timeout=0.5)
        except subprocess.TimeoutExpired:
            self._process.terminate()
            with contextlib.suppress(subprocess.TimeoutExpired):
                self._process.wait(timeout=2.0)
        self._conn.close()


__all__ = ["PlannerDied", "PlannerProcess"]

if __name__ == "__main__":  # the planner process (PlannerProcess): its end of the socket pair
    if "--above-ordinary-work" in sys.argv:
        _above_ordinary_work()
    _serve(Connection(int(sys.argv[1])))
