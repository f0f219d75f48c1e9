"""DDS links left open close themselves at interpreter exit, before the interpreter's teardown deletes
the Cyclone domains and entities (g1_control/hardware/links/dds.py: _close_links_at_exit): a process
whose links still stream from daemon threads (a writer on each side, a reader asking discovery too on each side) exits 0,
its links were closed by the exit hook, and the threads' last writes are dropped without an error
(CI's timing pass segfaulted once at exit after all its tests passed, stop 34)."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
import uuid
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]

SCRIPT = textwrap.dedent("""
    import atexit, sys, threading, time

    seen = {}

    def report():  # registered before the link module's hook, so it runs after it
        print("closed at exit:", seen["host"]._closed, seen["robot"]._closed, "errors:", seen["errors"], flush=True)

    atexit.register(report)
    from g1_control.hardware.links.dds import DdsLink
    from g1_control.hardware.unitree.messages import LowCmd, LowState

    partition = sys.argv[1]
    host, robot = DdsLink("host", "lo", 1, partition=partition), DdsLink("robot", "lo", 1, partition=partition)
    seen.update(host=host, robot=robot, errors=0)
    received = [0]

    def send(link, payload):
        while True:
            try:
                link.send(payload)
            except Exception:
                seen["errors"] += 1
            time.sleep(0.001)

    def receive(link):  # as a link backend's reader thread: samples, and discovery now and then
        while True:
            received[0] += len(link.receive(0.01))
            link.peer_writers()

    for target, args in ((send, (robot, LowState().to_dds())), (send, (host, LowCmd().to_dds())),
                         (receive, (host,)), (receive, (robot,))):
        threading.Thread(target=target, args=args, daemon=True).start()
    deadline = time.monotonic() + 10.0
    while received[0] < 20 and time.monotonic() < deadline:
        time.sleep(0.01)
    print("streaming:", received[0] >= 20, flush=True)
""")


def test_links_left_open_with_threads_streaming_are_closed_by_the_exit_hook():
    partition = f"g1test-exit-{os.getpid()}-{uuid.uuid4().hex[:8]}"
    done = subprocess.run([sys.executable, "-X", "faulthandler", "-c", SCRIPT, partition], check=False,
                          capture_output=True,
                          text=True, timeout=60, env={**os.environ, "PYTHONPATH": str(ROOT)})
    assert done.returncode == 0, done.stdout + done.stderr
    assert done.stdout.splitlines() == ["streaming: True", "closed at exit: True True errors: 0"], \
        done.stdout + done.stderr
    assert "Exception in thread" not in done.stderr and "Fatal Python error" not in done.stderr, done.stderr
