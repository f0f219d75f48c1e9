"""Scheduling priority for the processes that must keep time (the deploy's control phase, the robot
emulator, the fault suite's host).

On a shared host, ordinary work (builds, tests, other programs) competes for the cores. With the
kernel's autogroups (each login session gets an equal share, whatever its nice values) a control
loop at normal priority waits behind it for tens to hundreds of milliseconds and misses its
deadlines. Robot deployments run the controller at a real-time priority (ros2_control and Unitree's
own examples do), which ordinary work cannot delay: `realtime()` does that (SCHED_RR, every thread
of the process, threads created later inherit it) where the OS allows it (root or CAP_SYS_NICE),
and otherwise falls back to a lower nice value, then to nothing, saying so. The kernel keeps 5% of
every second for ordinary work (sched_rt_runtime_us), and every thread here sleeps between ticks.
"""

from __future__ import annotations

import contextlib
import logging
import os

log = logging.getLogger("g1_control.loop")

FALLBACK_NICE = -10


def _threads() -> list[int]:
    try:
        return [int(t) for t in os.listdir("/proc/self/task")]
    except OSError:
        return [0]


def _each_thread(fn) -> None:
    for tid in _threads():
        with contextlib.suppress(ProcessLookupError):  # the thread ended meanwhile
            fn(tid)


def get_nice() -> int:
    return os.getpriority(os.PRIO_PROCESS, 0)


def set_nice(nice: int) -> str:
    """Set the nice value of every thread of this process; return what was done, for the log."""
    current = get_nice()
    if nice == current:
        return f"nice {current}"
    try:
        _each_thread(lambda tid: os.setpriority(os.PRIO_PROCESS, tid, nice))
    except PermissionError:
        return f"nice {current} (nice {nice} not permitted)"
    return f"nice {nice}"


class Priority:
    """The scheduling of this process before `realtime()` changed it, to put back with `restore()`."""

    def __init__(self):
        self.policy = os.sched_getscheduler(0)
        self.param = os.sched_getparam(0)
        self.nice = get_nice()

    def restore(self) -> None:
        with contextlib.suppress(PermissionError, OSError):
            _each_thread(lambda tid: os.sched_setscheduler(tid, self.policy, self.param))
        set_nice(self.nice)


def realtime(priority: int) -> tuple[Priority, str]:
    """Run every thread of this process at SCHED_RR `priority` (1..99; 0: leave the scheduling alone),
    or failing that at nice FALLBACK_NICE. Returns (what to restore, what was done)."""
    before = Priority()
    if priority <= 0:
        return before, f"normal scheduling (nice {before.nice})"
    try:
        _each_thread(lambda tid: os.sched_setscheduler(tid, os.SCHED_RR, os.sched_param(priority)))
        return before, f"real-time (SCHED_RR {priority})"
    except (PermissionError, OSError) as exc:
        before.restore()
        done = set_nice(FALLBACK_NICE)
        log.warning("real-time scheduling not permitted (%s; needs root or CAP_SYS_NICE): %s; deadlines may be "
                    "missed on a busy host", exc, done)
        return before, f"{done} (real-time not permitted)"


@contextlib.contextmanager
def frozen_heap():
    """Inside: the objects alive at entry are moved out of the garbage collector's reach (gc.freeze),
    so a collection during a real-time loop scans only what the loop itself allocated. A full
    collection of a deploy process's heap takes 20-80 ms (its modules, the policy, MuJoCo's dry
    run): measured as ticks more than a period late, and LowCmd_ gaps of ~100 ms, in a 30-minute
    soak before this. Outside: the heap as it was (gc.unfreeze)."""
    import gc

    gc.collect()
    gc.freeze()
    try:
        yield
    finally:
        gc.unfreeze()
