"""Cyclone DDS entities are deleted only under the process-wide entity lock (hardware/links/dds.py).

CI's test run segfaulted in an emulator's state write (ddspy_write, which keeps the GIL) while other
threads of the process went on in Cyclone through ctypes (which lets them run beside it). Deletions are
what must never run beside a write, so:

- a link that looked at discovery (peer_writers) leaves nothing for the garbage collector once closed: the
  binding's built-in reader and its ReadCondition hold each other, and used to be deleted whenever the
  collector ran, in whichever thread, without the lock;
- an entity whose Python object dies in another thread (an owner dropped without close(), a test's own
  entity) waits for the lock before it is deleted."""

from __future__ import annotations

import gc
import threading
import uuid

import pytest

pytest.importorskip("cyclonedds")


def _made_since(before: set[int]) -> list[str]:
    from cyclonedds.core import Entity

    return sorted(type(e).__name__ for ref, e in list(Entity._entities.items()) if ref not in before)


def test_a_closed_link_that_read_discovery_leaves_nothing_for_the_garbage_collector():
    from cyclonedds.core import Entity

    from g1_control.hardware.links.dds import DdsLink

    partition = f"gc-{uuid.uuid4().hex[:8]}"
    robot = DdsLink("robot", "lo", 1, partition=partition)
    gc.collect()
    gc.disable()
    try:
        before = set(Entity._entities.keys())
        host = DdsLink("host", "lo", 1, partition=partition)
        robot.send(b"\x00" * 8)
        host.receive(0.01)
        counts = host.peer_writers()
        assert set(counts) == {"rt/lowstate", "rt/lowcmd"}
        made = _made_since(before)
        assert "BuiltinDataReader" in made and "DataWriter" in made, made
        host.close()
        assert _made_since(before) == [], "entities left to be deleted by the garbage collector, unlocked"
    finally:
        gc.enable()
        robot.close()


def test_an_entity_dropped_in_another_thread_is_deleted_only_under_the_entity_lock():
    from cyclonedds.core import Entity
    from cyclonedds.topic import Topic

    from g1_control.hardware.links.dds import _ENTITY_LOCK, domain_participant
    from g1_control.hardware.unitree import idl

    with _ENTITY_LOCK:
        participant = domain_participant("lo", 1)
        box = [Topic(participant, f"rt/gc_probe_{uuid.uuid4().hex[:8]}", idl.LowState_)]
    ref = box[0]._ref
    dropped = threading.Event()

    def drop() -> None:
        box.clear()  # the last reference: the binding deletes the topic here
        dropped.set()

    with _ENTITY_LOCK:
        thread = threading.Thread(target=drop, daemon=True)
        thread.start()
        assert not dropped.wait(0.5), "the topic was deleted while another thread held the entity lock"
        assert ref in Entity._entities
    thread.join(5.0)
    assert dropped.is_set() and ref not in Entity._entities
    with _ENTITY_LOCK:
        del participant

