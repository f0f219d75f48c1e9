"""The goal planner's own process: where whole-body plans are made beside a wall-clock loop.

A plan (footsteps for a carry, a grasp's four poses, a reach) takes 0.1-2 s of CPU. Made in a
thread beside the control loop, it shares the interpreter's lock with the loop and, where the
deploy runs every thread of its process at SCHED_RR (loop/priority.py), the loop's priority too:
measured over DDS against `g1 sim-robot` on 2 cores, the loop then waited up to 100 ms (one
round-robin time slice of the planner thread) and the safety layer tripped on "10 deadline
overruns within 1.0 s" as a pick's plans started. Here the planning runs in a process of its own,
started afresh (not forked: the parent runs DDS threads) one real-time priority below the thread that
starts it (the loop's, in a deploy), with its own PosePlanner: the loop preempts it whenever a tick
is due and never waits for its lock, and ordinary work on the host does not starve it.
It stops when its parent closes the socket (or dies).

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


@contextlib.contextmanager
def _scheduling_below_this_thread() -> Iterator[None]:
    """This thread one real-time priority lower for the block, so that a process started in it runs
    below the loop (which preempts it at once) but above ordinary work (which would otherwise starve
    a plan on a busy host: measured, a pick's plans took ~30 s of wall time at ordinary priority
    beside the emulator). At ordinary scheduling (or the lowest real-time priority) the process starts
    at ordinary scheduling, with this thread's nice value."""
    policy, param = os.sched_getscheduler(0), os.sched_getparam(0)
    if policy not in (os.SCHED_RR, os.SCHED_FIFO):
        yield
        return
    below = param.sched_priority - 1
    os.sched_setscheduler(0, *((policy, os.sched_param(below)) if below >= 1 else (os.SCHED_OTHER, os.sched_param(0))))
    try:
        yield
    finally:
        with contextlib.suppress(OSError):
            os.sched_setscheduler(0, policy, param)


class PlannerProcess:
    """One planner process (module docstring), started at once so that the first goal does not wait
    for its imports. It runs this module as a program (`python -m`), not multiprocessing's spawn,
    which would run the parent's main script again in the child."""

    def __init__(self) -> None:
        parent, child = socket.socketpair()
        package_root = str(Path(__file__).resolve().parents[3])  # the g1_control the parent runs
        env = dict(os.environ, PYTHONPATH=os.pathsep.join([package_root, *filter(None, [os.environ.get("PYTHONPATH")])]))
        with _scheduling_below_this_thread():
            self._process = subprocess.Popen([sys.executable, "-m", __name__, str(child.fileno())],
                                             pass_fds=[child.fileno()], env=env, stdin=subprocess.DEVNULL)
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
    _serve(Connection(int(sys.argv[1])))
