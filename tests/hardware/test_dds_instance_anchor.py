"""The keyless-instance anchor (hardware/links/dds.py: _anchor_keyless_instance): the Cyclone DDS binding
(0.10.x) maps every keyless sample of a domain, whatever its type, to one shared instance that keeps a
pointer to the type of the sample that made it; the anchor makes that first sample, from a type that
lives as long as the process (the cause of the CI segfaults in dds_write, docs/robot_facts.md)."""

from __future__ import annotations

import uuid


def _instance_of_a_sample_through(partition: str) -> int:
    """Send one LowState_-sized payload robot -> host on fresh links; the instance handle it arrived with."""
    from cyclonedds._clayer import ddspy_take

    from g1_control.hardware.links.dds import DdsLink

    robot, host = DdsLink("robot", "lo", 1, partition=partition), DdsLink("host", "lo", 1, partition=partition)
    try:
        robot.send(b"\x00\x01\x00\x00" + b"\x00" * 1000)
        for _ in range(200):
            host._waitset.wait(10_000_000)
            with host._io_lock:
                samples = ddspy_take(host._reader._ref, 4)
            if samples:
                return int(samples[0][1].instance_handle)
        raise AssertionError("the sample never arrived")
    finally:
        robot.close()
        host.close()


def test_every_keyless_sample_maps_to_the_anchors_instance_which_outlives_every_link():
    """The instance handle of a LowState_ sample is the anchor's, on links made before and after other links
    were closed (their types freed): the shared instance is the anchor's, and the anchor keeps it."""
    from g1_control.hardware.links.dds import _ENTITY_LOCK, _anchors, domain_participant

    with _ENTITY_LOCK:
        participant = domain_participant("lo", 1)
        del participant
    _participant, _topic, _writer, reader = _anchors[1]
    [anchor] = reader.read(N=1)
    first = _instance_of_a_sample_through(f"anchor-{uuid.uuid4().hex[:8]}")
    later = _instance_of_a_sample_through(f"anchor-{uuid.uuid4().hex[:8]}")
    assert first == later == anchor.sample_info.instance_handle
