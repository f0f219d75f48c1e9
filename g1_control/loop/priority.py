"""Scheduling priority for the processes that must keep time (the deploy's loop, the robot emulator).

On a shared host, ordinary work (builds, tests, other programs) competes for the cores; a control
loop at the same priority waits behind it for tens to hundreds of milliseconds and misses its
deadlines. Real robot deployments give the controller a higher priority (or a core of its own);
here a lower nice value does it: CFS then wakes the loop ahead of ordinary work and gives it the
larger share when the cores are busy, without the starvation risk of a real-time policy.
"""

from __future__ import annotations

import logging
import os

log = logging.getLogger("g1_control.loop")


def set_nice(nice: int) -> str:
    """Set the nice value of every thread of this process (threads created later inherit it) where
    the OS allows it (lowering it needs root or CAP_SYS_NICE); return what was done, for the log."""
    current = os.getpriority(os.PRIO_PROCESS, 0)
    if nice == current:
        return f"nice {current}"
    try:
        tids = [int(t) for t in os.listdir("/proc/self/task")]
    except OSError:
        tids = [0]
    try:
        for tid in tids:
            try:
                os.setpriority(os.PRIO_PROCESS, tid, nice)
            except ProcessLookupError:
                pass  # the thread ended meanwhile
    except PermissionError:
        log.warning("cannot set nice %d (needs root or CAP_SYS_NICE); running at nice %d: deadlines may be missed "
                    "on a busy host", nice, current)
        return f"nice {current} (nice {nice} not permitted)"
    return f"nice {nice}"


def get_nice() -> int:
    return os.getpriority(os.PRIO_PROCESS, 0)
