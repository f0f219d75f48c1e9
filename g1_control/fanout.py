"""Fan independent, seeded work out over processes on this machine or over a Ray cluster.

Benches and builds that run many independent trials (`g1 bench execution`, `g1 bench program`,
the motion library's rollouts) give `fan_out` a function of one task and the tasks, and get the
results back in the order of the tasks, whoever ran them:

    results = fan_out(run_task, tasks)                      # one after another, in this process
    results = fan_out(run_task, tasks, jobs=2)              # 2 worker processes here
    results = fan_out(run_task, tasks, ray="local")         # a local Ray on every core
    results = fan_out(run_task, tasks, ray="10.0.0.5:6379") # a running Ray cluster's head

The contract that makes every way give the same results: `run_task` is a module-level function
(workers import it by name) whose result depends on its task alone: seeds travel inside the task,
nothing is read from a clock or from state shared between tasks, nothing is written to files (a
result the caller wants on disk comes back in the result). Tasks and results are picklable.
Timing figures a task measures (wall time, CPU per tick) are the one part that differs.

Ray is optional (`pip install 'g1-control[ray]'`); the cluster's nodes need the same g1-control
installed (scripts/setup.sh). A command line takes `--jobs N` and `--ray ADDRESS` from
`add_arguments` and hands them to `fan_out` unchanged.
"""

from __future__ import annotations

import logging
import os
import socket
from collections.abc import Callable, Iterable, Iterator
from concurrent.futures import ProcessPoolExecutor
from typing import TYPE_CHECKING, Any, TypeVar

from g1_control.errors import FanOutError

if TYPE_CHECKING:
    import argparse

T = TypeVar("T")
R = TypeVar("R")

LOCAL = "local"
CONNECT_TIMEOUT_S = 5.0
"""How long a cluster's head may take to accept a connection before --ray gives up on it."""
LOCAL_OBJECT_STORE_BYTES = 256 * 2**20
"""A local Ray's shared-memory store: results are small (figures, a clip, one log for a video)."""
RAY_INSTALL = "pip install 'g1-control[ray]' (or: pip install ray)"
ADDRESS_HELP = ("local (a Ray on every core of this machine), local:CPUS, or HOST:PORT of a running Ray cluster's "
                "head (what `ray start --head` prints, port 6379 by default)")


def add_arguments(parser: argparse.ArgumentParser, *, jobs_default: int = 1, what: str = "trials") -> None:
    """--jobs and --ray, the same on every command that fans work out."""
    parser.add_argument("--jobs", type=int, default=jobs_default,
                        help=f"{what}: worker processes on this machine (default {jobs_default}); "
                        "the results do not depend on it")
    parser.add_argument("--ray", metavar="ADDRESS",
                        help=f"{what}: run them on a Ray cluster instead of --jobs processes, the same results for "
                        f"the same seeds: {ADDRESS_HELP}; needs {RAY_INSTALL}")


def describe(jobs: int = 1, ray: str | None = None) -> str:
    """Where the work runs, for a bench's first line."""
    if ray is not None:
        return f"on Ray ({ray})"
    return "in this process" if jobs <= 1 else f"in {jobs} processes"


def fan_out(work: Callable[[T], R], tasks: Iterable[T], *, jobs: int = 1, ray: str | None = None) -> Iterator[R]:
    """`work(task)` for every task, results in the order of the tasks (each as soon as it and
    those before it are done). `jobs` worker processes on this machine (1: in this process), or
    the Ray cluster at `ray` (module docstring). Bad arguments, a missing Ray or a cluster that
    cannot be reached raise FanOutError here, before any task runs; a task's own error comes out
    of the iteration."""
    todo = list(tasks)
    if jobs < 1:
        raise FanOutError(f"--jobs {jobs}: expected 1 or more worker processes")
    if ray is not None:
        session = _RaySession(ray)
        return session.results(work, todo)
    if jobs > 1 and len(todo) > 1:
        return _in_processes(work, todo, min(jobs, len(todo)))
    return (work(task) for task in todo)


def _in_processes(work: Callable[[T], R], tasks: list[T], jobs: int) -> Iterator[R]:
    with ProcessPoolExecutor(max_workers=jobs) as pool:
        yield from pool.map(work, tasks)


def parse_address(address: str) -> tuple[str | None, int | None]:
    """(cluster address, None) or (None, CPUs of a local Ray: None for every core)."""
    text = address.strip()
    if text == LOCAL:
        return None, None
    if text.startswith(LOCAL + ":"):
        cpus = text[len(LOCAL) + 1:]
        if not cpus.isdigit() or int(cpus) < 1:
            raise FanOutError(f"--ray {address}: expected local:CPUS with CPUS a whole number >= 1")
        return None, int(cpus)
    host, _, port = text.removeprefix("ray://").rpartition(":")
    if not host or not port.isdigit():
        raise FanOutError(f"--ray {address!r}: expected {ADDRESS_HELP}")
    return text, None


def _import_ray() -> Any:
    try:
        import ray
    except ImportError as exc:
        raise FanOutError(f"--ray needs Ray, which is not installed here: {RAY_INSTALL}") from exc
    return ray


def check_reachable(address: str, timeout_s: float = CONNECT_TIMEOUT_S) -> None:
    """Refuse an address where nothing accepts a connection, before Ray's own client (which retries
    for minutes) is asked to join it."""
    host, _, port = address.removeprefix("ray://").rpartition(":")
    try:
        socket.create_connection((host.strip("[]"), int(port)), timeout=timeout_s).close()
    except OSError as exc:
        why = exc.strerror or str(exc) or type(exc).__name__
        raise FanOutError(f"--ray {address}: no Ray cluster answers there ({why} within {timeout_s:.0f} s); start one "
                          "with `ray start --head` on that machine, or run with --ray local") from exc


def _worker_facts() -> str:
    """Run on a worker before any task: the g1_control it imports (the cluster's install)."""
    import g1_control

    return os.path.dirname(g1_control.__file__)


_INIT_QUIET = {"include_dashboard": False, "log_to_driver": False, "logging_level": logging.ERROR}
LOCAL_START_TRIES = 3
"""A local Ray's node gives up when its raylet has not registered within 30 s (fixed in Ray), which
happens on a heavily loaded machine; a fresh start usually comes up."""


def start_local_ray(cpus: int | None = None, tries: int = LOCAL_START_TRIES) -> None:
    """Start a Ray on this machine with `cpus` CPUs (None: every core), bound to loopback (it
    serves this machine only), quiet (workers' output stays in Ray's logs), and a small store."""
    ray = _import_ray()
    for attempt in range(1, tries + 1):
        try:
            ray.init(num_cpus=cpus or os.cpu_count(), object_store_memory=LOCAL_OBJECT_STORE_BYTES,
                     _node_ip_address="127.0.0.1", **_INIT_QUIET)
            return
        except Exception as exc:
            ray.shutdown()
            if attempt == tries or "timed out during startup" not in str(exc):
                raise


class _RaySession:
    """A connection to a Ray cluster (started here for `local`) for one fan-out; a Ray that the
    caller already initialised is used as it is and left running."""

    def __init__(self, address: str):
        cluster, cpus = parse_address(address)
        self.address = address
        self.ray = _import_ray()
        if cluster is not None:
            check_reachable(cluster)
        self.owned = not self.ray.is_initialized()
        if self.owned:
            try:
                if cluster is None:
                    start_local_ray(cpus)
                else:
                    self.ray.init(address=cluster, **_INIT_QUIET)
            except Exception as exc:  # Ray raises bare Exception for a node that did not come up
                raise FanOutError(f"--ray {address}: Ray could not {'start' if cluster is None else 'join'} "
                                  f"the cluster: {exc}") from exc
        try:
            self.ray.get(self.ray.remote(_worker_facts).remote())
        except Exception as exc:
            self.close()
            raise FanOutError(f"--ray {address}: the cluster's workers cannot import g1_control ({exc}); install "
                              "the same g1-control on every node (scripts/setup.sh)") from exc

    def results(self, work: Callable[[T], R], tasks: list[T]) -> Iterator[R]:
        try:
            remote = self.ray.remote(num_cpus=1)(work)
            refs = [remote.remote(task) for task in tasks]
            for ref in refs:
                yield self.ray.get(ref)
        finally:
            self.close()

    def close(self) -> None:
        if self.owned and self.ray.is_initialized():
            self.ray.shutdown()
