"""Suite-wide fixtures."""

from __future__ import annotations

import pytest

TIMING_RT_PRIORITY = 10
"""Real-time priority for the system under test in `timing` tests (below g1 deploy's 20 and the
emulator's 30, which they raise to where they start them)."""


@pytest.fixture(autouse=True)
def _realtime_for_timing_tests(request):
    """A `timing` test measures the robot path as it runs on a robot: at a real-time priority (see
    g1_control/loop/priority.py), so that other work on the host (CI's load generator, other jobs)
    cannot starve it. Subprocesses started by the test inherit it. Without permission: as it is.
    The test process's heap (everything the suite has loaded so far) is frozen for the test, as the
    deploy freezes its own (loop/priority.frozen_heap): an in-process robot and deploy share one
    GIL, and a full collection of a late-suite heap stalled both past the 250 ms stale-state limit."""
    if request.node.get_closest_marker("timing") is None:
        yield
        return
    from g1_control.loop.priority import frozen_heap, realtime

    normal, _ = realtime(TIMING_RT_PRIORITY)
    try:
        with frozen_heap():
            yield
    finally:
        normal.restore()


@pytest.fixture(autouse=True)
def _working_directory_is_scratch(tmp_path, monkeypatch):
    """Every test runs in its own empty working directory: runs and deploys write their run folders
    under the launch file's output.dir (relative: the working directory), never into the
    repository, and a test that reads a relative path fails here rather than passing by luck."""
    monkeypatch.chdir(tmp_path)
