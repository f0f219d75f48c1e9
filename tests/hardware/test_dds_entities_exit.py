"""The other owners of Cyclone DDS entities (hardware/links/dds.py: DdsEntities) besides DdsLink: the Dex3
hands' link and emulator, the motion service's client and emulator, the ROS 2 bridge and pose topics. Their
entities are made, used and deleted under the process-wide entity lock, like a link's:

- a process that leaves them all open, each with a thread streaming on it, exits 0: the exit hook closed
  every one before the interpreter's teardown (the Dex3 link by its own close, which damps first), no thread raised, no fatal
  error (before, none of them was closed at exit: teardown deleted their entities in no order while their
  threads wrote);
- a serving thread that outlives close()'s join(timeout=2.0) (held inside a call) finds its entities
  closed when it goes on: its answer is dropped, nothing raises, the thread ends (before, close() only
  joined, and the late answer still went out)."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
import threading
import time
import uuid
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]

pytestmark = pytest.mark.timing

SCRIPT = textwrap.dedent("""
    import atexit, sys, threading, time
    import numpy as np

    owners, errors = {}, []

    def report():  # registered before the DDS module's hook, so it runs after it
        print("closed at exit:", {name: o._dds.closed for name, o in owners.items()}, flush=True)
        print("the hand link's own close (damping first) ran:", owners["dex3_link"]._closed, flush=True)
        print("errors:", errors, flush=True)

    atexit.register(report)
    from g1_control.hardware.hand_link import Dex3HandLink
    from g1_control.hardware.links.dds import domain_participant
    from g1_control.hardware.ros2.topics import PoseTopicReader, PoseTopicWriter
    from g1_control.hardware.unitree.motion_service import MotionServiceClient, MotionServiceEmulator
    from g1_control.robot import dex3
    from g1_control.sim.dex3_hands import Dex3HandsEmulator
    from g1_control.teleop.ros2 import Ros2Bridge
    from g1_control.types import FingerCommand

    partition = sys.argv[1]
    owners["dex3_emulator"] = Dex3HandsEmulator("lo", 1, partition=partition).start()
    hands = owners["dex3_link"] = Dex3HandLink("lo", 1, partition=partition)
    participant = domain_participant("lo", 1)
    owners["motion_emulator"] = MotionServiceEmulator(participant, partition, active_mode="ai")
    client = owners["motion_client"] = MotionServiceClient(participant, partition, timeout_s=1.0)
    writer = owners["pose_writer"] = PoseTopicWriter("lo", 1, "mocap_pose", partition)
    reader = owners["pose_reader"] = PoseTopicReader("lo", 1, "mocap_pose", partition)
    bridge = owners["ros2_bridge"] = Ros2Bridge("lo", 1, partition=partition)
    counts = {"hand": 0, "service": 0, "pose": 0, "bridge": 0}

    def forever(name, step):
        def run():
            while True:
                try:
                    step()
                    counts[name] += 1
                except Exception as exc:  # a closed client's call raises by design; anything else is a fault
                    if not (name == "service" and "closed client" in str(exc)):
                        errors.append(f"{name}: {type(exc).__name__}: {exc}")
                    return
                time.sleep(0.002)
        threading.Thread(target=run, daemon=True).start()

    hand_cmd = FingerCommand(q_rad=np.zeros(dex3.NUM_MOTORS), kp=np.full(dex3.NUM_MOTORS, 1.0),
                             kd=np.full(dex3.NUM_MOTORS, 0.1))
    forever("hand", lambda: hands.write("left", hand_cmd))
    forever("service", client.check_mode)
    forever("pose", lambda: (writer.write(time.time(), (0.0, 0.0, 0.8), (1.0, 0.0, 0.0, 0.0)), reader.take()))
    forever("bridge", lambda: bridge.poll(time.monotonic()))
    hands.wait_for_state(("left", "right"), 10.0)
    deadline = time.monotonic() + 10.0
    while time.monotonic() < deadline and (min(counts.values()) < 5 or reader.received < 5):
        time.sleep(0.01)
    print("streaming:", min(counts.values()) >= 5 and reader.received >= 5, flush=True)
""")

OWNERS = ("dex3_emulator", "dex3_link", "motion_emulator", "motion_client", "pose_writer", "pose_reader",
          "ros2_bridge")


def test_owners_left_open_with_threads_streaming_are_closed_by_the_exit_hook():
    partition = f"g1test-owners-{os.getpid()}-{uuid.uuid4().hex[:8]}"
    done = subprocess.run([sys.executable, "-X", "faulthandler", "-c", SCRIPT, partition], check=False,
                          capture_output=True, text=True, timeout=90, env={**os.environ, "PYTHONPATH": str(ROOT)})
    assert done.returncode == 0, done.stdout + done.stderr
    closed = str(dict.fromkeys(OWNERS, True))
    assert done.stdout.splitlines() == ["streaming: True", f"closed at exit: {closed}",
                                        "the hand link's own close (damping first) ran: True",
                                        "errors: []"], done.stdout + done.stderr
    assert "Exception in thread" not in done.stderr and "Fatal Python error" not in done.stderr, done.stderr


def test_a_serving_thread_that_outlives_the_join_sends_nothing_once_closed(monkeypatch):
    from g1_control.errors import MotionServiceError
    from g1_control.hardware.links.dds import domain_participant
    from g1_control.hardware.unitree.motion_service import (
        API_RELEASE_MODE,
        MotionServiceClient,
        MotionServiceEmulator,
    )

    partition = f"g1test-late-{os.getpid()}-{uuid.uuid4().hex[:8]}"
    raised: list = []
    monkeypatch.setattr(threading, "excepthook", raised.append)
    inside, release = threading.Event(), threading.Event()

    def held(_mode: str) -> None:  # the serving thread, inside a call, held past close()'s join timeout
        inside.set()
        release.wait(10.0)

    participant = domain_participant("lo", 1)
    service = MotionServiceEmulator(participant, partition, active_mode="ai", on_change=held)
    client = MotionServiceClient(participant, partition, timeout_s=4.0)
    answers: list = []

    def ask() -> None:
        try:
            client.release_mode()
            answers.append("answered")
        except MotionServiceError as exc:
            answers.append(str(exc))

    asking = threading.Thread(target=ask)
    asking.start()
    try:
        assert inside.wait(5.0), "the emulator never got the release"
        t0 = time.monotonic()
        service.close()  # the join gives up after 2 s; the entities are deleted under the lock
        assert time.monotonic() - t0 >= 1.9 and service._thread.is_alive(), "the thread outlived the join"
        assert service._dds.closed
    finally:
        release.set()
        asking.join(10.0)
        client.close()
    service._thread.join(2.0)
    assert not service._thread.is_alive(), "the late thread ended"
    assert service.calls == [API_RELEASE_MODE] and service.active_mode == ""
    assert answers == ["the robot's motion service did not answer api 1003 within 4.0 s; is the robot on this "
                       "interface/domain? If you put it in debug mode with the remote instead, skip the release "
                       "(--no-release-motion-service)"], answers
    assert raised == [], raised
