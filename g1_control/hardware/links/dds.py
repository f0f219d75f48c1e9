"""The G1's DDS link on Cyclone DDS 0.10.x: rt/lowcmd (host -> robot), rt/lowstate (robot -> host).

Samples are encoded by the numpy codecs in unitree_hg.py (~10 us) and handed to Cyclone as bytes
through the binding's C layer, instead of through IdlStruct.serialize (~170 us per LowCmd, ~370 us
per LowState to decode in pure Python); the topics are still registered with the IdlStruct types
of unitree_idl.py so that discovery and type matching with the robot are unchanged.

One process holds one Cyclone domain per domain id, configured here with the named interface
only. On loopback, which has no multicast, peers are found by unicast to 127.0.0.1 with automatic
participant indices (ports 7400 + 250 * domain + 10 + 2 * index).
"""

from __future__ import annotations

import atexit
import threading
import weakref
from typing import Any
from xml.sax.saxutils import quoteattr

from g1_control.errors import TransportError
from g1_control.hardware.links.base import Link, Side
from g1_control.hardware.links.network import LOOPBACK, check_interface
from g1_control.hardware.unitree.messages import LOWCMD_TOPIC, LOWSTATE_TOPIC

MAX_LOOPBACK_PARTICIPANTS = 32
"""Automatic participant indices on loopback (Cyclone's default, 9, allows only ~10 processes)."""

_domains: dict[int, tuple[str, object]] = {}
_domains_lock = threading.Lock()
_anchors: dict[int, tuple[Any, ...]] = {}
"""Per domain, the entities of _anchor_keyless_instance (kept for the life of the process)."""

ANCHOR_TOPIC = "g1_control/keyless_instance_anchor"
"""The process-local topic of _anchor_keyless_instance (its own partition: no other process matches it)."""


def import_cyclonedds():
    try:
        import cyclonedds  # noqa: F401
        from cyclonedds import _clayer  # noqa: F401
        from cyclonedds.domain import Domain  # noqa: F401
    except ImportError as exc:
        raise TransportError(
            f"the DDS transport needs the cyclonedds 0.10.x Python binding ({exc}); "
            "install it with scripts/install_cyclonedds.sh"
        ) from None


def cyclone_config(interface: str) -> str:
    """Cyclone DDS XML confining the domain to `interface` (unicast discovery on loopback)."""
    if interface == LOOPBACK:
        discovery = (
            "<Discovery><ParticipantIndex>auto</ParticipantIndex>"
            f"<MaxAutoParticipantIndex>{MAX_LOOPBACK_PARTICIPANTS}</MaxAutoParticipantIndex>"
            '<Peers><Peer address="127.0.0.1"/></Peers></Discovery>'
        )
        multicast = "<AllowMulticast>false</AllowMulticast>"
    else:
        discovery, multicast = "", ""
    return (
        '<CycloneDDS xmlns="https://cdds.io/config"><Domain id="any"><General><Interfaces>'
        f'<NetworkInterface name={quoteattr(interface)} priority="default" multicast="default"/>'
        f"</Interfaces>{multicast}</General>{discovery}</Domain></CycloneDDS>"
    )


def domain_participant(interface: str, domain_id: int):
    """A participant on `domain_id` bound to `interface` (one domain configuration per process)."""
    import_cyclonedds()
    from cyclonedds.domain import Domain, DomainParticipant

    check_interface(interface)
    if not 0 <= int(domain_id) <= 232:
        raise TransportError(f"DDS domain id must be 0..232; got {domain_id} (the robot uses 0, simulation 1)")
    with _domains_lock:
        if domain_id in _domains:
            bound, _ = _domains[domain_id]
            if bound != interface:
                raise TransportError(
                    f"DDS domain {domain_id} is already bound to interface '{bound}' in this process; "
                    f"cannot also bind it to '{interface}'"
                )
        else:
            _domains[domain_id] = (interface, Domain(domain_id, cyclone_config(interface)))
            _anchors[domain_id] = _anchor_keyless_instance(domain_id)
    return DomainParticipant(domain_id)


def _anchor_keyless_instance(domain_id: int) -> tuple[Any, ...]:
    """Write the domain's first keyless sample from a topic that lives as long as the process, and keep it.

    Why (the CI segfaults of stops 27-36, read from a core file: dds_write -> ddsi_tkmap_find -> a freed
    instance): Cyclone maps every sample's key to an instance in one table per domain (the "tkmap"), shared
    by all topics. The Python binding (0.10.x, clayer/pysertype.c) gives every keyless sample the same hash
    and calls any two keyless samples equal, whatever their types, so all our topics (LowCmd_, LowState_, the
    motion service's, the hands', ROS 2's: all keyless) share one instance. That instance keeps the first
    sample that made it, and that sample points at its topic type without holding it; the binding's key
    comparison reads the type's `keyless` flag through that pointer. Once that type's topics are all deleted
    (a motion-service client closed while the robot link streams, tests making and closing links), the
    flag is read from freed memory: a lookup can then miss the instance and make a second one, and the
    table's removal, which removes the first entry that compares equal, can take out the wrong one, leaving
    a freed instance in the table for the next write to crash on.
    So the first keyless sample of each domain is this anchor's, its type is held by a topic that is never
    deleted, and a reader of this process keeps the sample (never taken), so the shared instance is never
    freed and its type pointer stays valid. The anchor's participant, writer and reader live in a partition
    of their own; discovery announces them, nothing else matches them."""
    from cyclonedds.domain import DomainParticipant
    from cyclonedds.pub import DataWriter, Publisher
    from cyclonedds.qos import Policy, Qos
    from cyclonedds.sub import DataReader, Subscriber
    from cyclonedds.topic import Topic

    from g1_control.hardware.links.anchor_idl import InstanceAnchor_ as anchor_type
    participant = DomainParticipant(domain_id)
    topic = Topic(participant, ANCHOR_TOPIC, anchor_type)
    group = Qos(Policy.Partition([f"g1_control_anchor_{threading.get_native_id()}_{id(participant):x}"]))
    qos = Qos(Policy.Reliability.Reliable(1_000_000_000), Policy.History.KeepLast(1),
              Policy.Durability.TransientLocal)
    writer = DataWriter(Publisher(participant, qos=group), topic, qos=qos)
    reader = DataReader(Subscriber(participant, qos=group), topic, qos=qos)
    writer.write(anchor_type(1))
    if len(reader.read(N=1)) != 1:
        raise TransportError(f"DDS domain {domain_id}: the keyless-instance anchor was not delivered in-process")
    return participant, topic, writer, reader


_ENTITY_LOCK = threading.Lock()
"""Held by every link's send/take and close, process-wide: Cyclone DDS (0.10) delivers a write to
the readers of the same process inline, and deleting a link's entities while another link's
thread writes on the same domain segfaulted the process (seen in the test suite under load: an
emulator's state write while a host link closed). Uncontended it costs well under a microsecond."""


_open_links: weakref.WeakSet[DdsLink] = weakref.WeakSet()
"""The links of this process not closed yet (closed at exit by _close_links_at_exit)."""
_open_owners: weakref.WeakSet[DdsEntities] = weakref.WeakSet()
"""The other owners of Cyclone entities not closed yet (DdsEntities: Dex3 hands, motion service, ROS 2)."""
_exiting = False
"""Set at interpreter exit: a send on a link closed by the exit hook is dropped instead of raising."""


def _close_links_at_exit() -> None:
    """Close every link still open before the interpreter tears its modules down. Teardown deletes the
    Cyclone domains and whatever entities are still referenced in no particular order, while daemon
    threads (a link backend's 500 Hz writer, an emulator's state stream) may still write on them:
    deleting entities while another thread writes on the same domain has crashed this process before
    (see _ENTITY_LOCK). Closed here under that lock, the links' threads no longer reach Cyclone.
    (CI's timing pass segfaulted once at exit after all its tests passed, stop 34.)
    The other owners (DdsEntities) close first: some use a link's participant (the motion-service
    emulator beside the emulated robot's link), which closing the link deletes."""
    global _exiting
    with _ENTITY_LOCK:
        _exiting = True
    for owner in list(_open_owners):
        owner.close_at_exit()
    for link in list(_open_links):
        link.close()


atexit.register(_close_links_at_exit)


class DdsEntities:
    """The Cyclone entities (participant, topics, publishers, writers, readers, waitsets, conditions)
    of one owner besides a DdsLink: the Dex3 hands' link and emulator, the motion service's client and
    emulator, the ROS 2 bridge and topics. Like a DdsLink's, they are made, written, taken and deleted
    under the process-wide _ENTITY_LOCK; once closed no call reaches Cyclone (a write is dropped, a
    take is empty), so an owner's thread that outlived its join(timeout) stops touching them instead
    of writing on deleted entities; an owner still open at interpreter exit is closed by
    _close_links_at_exit (`on_exit`: the owner's own close, e.g. one that damps the hands first).

        with entities.lock():            # making them: under the lock
            entities.add("writer", DataWriter(...))
            entities.attach("waitset", "condition")
        entities.write("writer", sample)   # False (nothing sent) once closed
        entities.take("reader", 16)        # [] once closed
        entities.close()                   # under the lock: every entity deleted, newest first
    """

    def __init__(self, on_exit: Any = None):
        """on_exit: a bound method of the owner (held weakly: an owner nobody holds is not kept alive)."""
        self._entities: dict[str, Any] = {}
        self._attached: list[tuple[str, str]] = []
        self._closed = False
        self._on_exit = weakref.WeakMethod(on_exit) if on_exit is not None else None
        _open_owners.add(self)

    @property
    def closed(self) -> bool:
        return self._closed

    def lock(self) -> threading.Lock:
        """The lock to hold while the owner makes its entities (`with entities.lock(): ...`)."""
        return _ENTITY_LOCK

    def add(self, name: str, entity: Any) -> Any:
        """Keep `entity` (call inside lock()); returns it."""
        if self._closed:
            raise TransportError(f"DDS entity '{name}' added after its owner closed")
        self._entities[name] = entity
        return entity

    def attach(self, waitset: str, condition: str) -> None:
        """Attach entity `condition` to waitset `waitset` (inside lock()); close() detaches it first."""
        self._entities[waitset].attach(self._entities[condition])
        self._attached.append((waitset, condition))

    def get(self, name: str) -> Any:
        """The entity `name` (TransportError once closed: for the owner's thread-less calls)."""
        with _ENTITY_LOCK:
            if self._closed:
                raise TransportError(f"DDS entity '{name}' used after its owner closed")
            return self._entities[name]

    def write(self, name: str, sample: Any) -> bool:
        """Write `sample` on writer `name` under the lock; False (nothing written) once closed."""
        with _ENTITY_LOCK:
            if self._closed:
                return False
            self._entities[name].write(sample)
            return True

    def take(self, name: str, n: int) -> list:
        """Up to `n` samples of reader `name` under the lock; [] once closed."""
        with _ENTITY_LOCK:
            return [] if self._closed else list(self._entities[name].take(n))

    def wait(self, name: str, timeout_s: float) -> None:
        """Block on waitset `name` up to `timeout_s` (not under the lock, as DdsLink.receive waits);
        returns at once once closed. The reference held while waiting is dropped under the lock."""
        with _ENTITY_LOCK:
            if self._closed:
                return
            waitset = self._entities[name]
        try:
            waitset.wait(int(timeout_s * 1e9))
        finally:
            with _ENTITY_LOCK:
                del waitset

    def close(self) -> bool:
        """Delete every entity under the lock, newest first; False when already closed."""
        with _ENTITY_LOCK:
            if self._closed:
                return False
            self._closed = True
            _open_owners.discard(self)
            for waitset, condition in self._attached:
                self._entities[waitset].detach(self._entities[condition])
            while self._entities:
                entity = self._entities.popitem()[1]
                del entity
        return True

    def close_at_exit(self) -> None:
        """What _close_links_at_exit calls: the owner's own close where it gave one, else close()."""
        on_exit = self._on_exit() if self._on_exit is not None else None
        if on_exit is not None and not self._closed:
            on_exit()
        self.close()


class DdsLink(Link):
    """One side of the G1 low-level DDS stream."""

    wire = "dds"

    def __init__(self, side: Side, interface: str, domain_id: int = 0, partition: str | None = None,
                 history_depth: int = 32):
        super().__init__(side)
        self.interface, self.domain_id, self.partition = interface, int(domain_id), partition
        import_cyclonedds()
        from cyclonedds.core import InstanceState, ReadCondition, SampleState, ViewState, WaitSet
        from cyclonedds.pub import DataWriter, Publisher
        from cyclonedds.qos import Policy, Qos
        from cyclonedds.sub import DataReader, Subscriber
        from cyclonedds.topic import Topic

        from g1_control.hardware.unitree import idl as unitree_idl

        with _ENTITY_LOCK:  # made under the process-wide lock, as they are used and deleted
            participant = domain_participant(interface, self.domain_id)
            cmd_topic = Topic(participant, LOWCMD_TOPIC, unitree_idl.LowCmd_)
            state_topic = Topic(participant, LOWSTATE_TOPIC, unitree_idl.LowState_)
            out_topic, in_topic = (cmd_topic, state_topic) if side == "host" else (state_topic, cmd_topic)
            # A partition isolates concurrent test runs that share loopback and domain 1 on one host;
            # the robot itself publishes in the default partition, so real use passes None.
            group_qos = Qos(Policy.Partition([partition])) if partition else None
            self._participant = participant
            # LowCmd_ out and LowState_ in on the host side, the reverse on the robot side.
            self._writer: DataWriter[Any] = DataWriter(Publisher(participant, qos=group_qos), out_topic)
            self._reader: DataReader[Any] = DataReader(
                Subscriber(participant, qos=group_qos), in_topic,
                qos=Qos(Policy.Reliability.BestEffort, Policy.History.KeepLast(history_depth)),
            )
            self._waitset = WaitSet(participant)
            self._condition = ReadCondition(self._reader, SampleState.Any | ViewState.Any | InstanceState.Any)
            self._waitset.attach(self._condition)
        self._depth = history_depth
        from cyclonedds._clayer import ddspy_take, ddspy_write

        self._write, self._take = ddspy_write, ddspy_take
        self._topics = (LOWSTATE_TOPIC, LOWCMD_TOPIC)
        self._own_writer = str(self._writer.guid)
        self._publications: Any = None
        """The built-in DCPSPublication reader, made on the first peer_writers()."""
        self._writers: dict[int, tuple[str, str]] = {}
        self._peer_lock = threading.Lock()
        """Discovered writers on our two topics and partition: instance handle -> (topic, guid)."""
        self._closed = False
        self._io_lock = _ENTITY_LOCK
        _open_links.add(self)

    @property
    def participant(self):
        """The DDS participant of this link (for RPC on the same domain: the motion service)."""
        return self._participant

    def describe(self) -> str:
        where = f"interface {self.interface}, domain {self.domain_id}"
        return f"DDS ({where}{', partition ' + self.partition if self.partition else ''})"

    def send(self, payload: bytes) -> None:
        with self._io_lock:
            if self._closed:
                if _exiting:  # a daemon thread's last writes while the interpreter exits
                    return
                raise TransportError(f"DDS write on {self.describe()}: the link is closed")
            ret = self._write(self._writer._ref, payload)
        if ret < 0:
            raise TransportError(f"DDS write on {self.describe()} failed with code {ret}")
        self._count("sent")

    def receive(self, timeout_s: float) -> list[bytes]:
        return [payload for payload, _ in self.receive_tagged(timeout_s)]

    def receive_tagged(self, timeout_s: float) -> list[tuple[bytes, int | None]]:
        samples = self._take_now()
        if isinstance(samples, int) or not samples:
            with self._io_lock:
                if self._closed:
                    return []
                waitset = self._waitset
            waitset.wait(int(timeout_s * 1e9))
            samples = self._take_now()
            if isinstance(samples, int):
                return []
        tagged = [(data, info.publication_handle) for data, info in samples if info.valid_data]
        self._count("received", len(tagged))
        return tagged

    def peer_writers(self) -> dict[str, int]:
        """Writers of rt/lowstate and rt/lowcmd in this domain and partition, from DDS discovery (the
        built-in DCPSPublication topic), not counting this link's own writer. New discovery samples
        only are taken each call, so a call costs little once the domain is known."""
        from cyclonedds.builtin import BuiltinDataReader, BuiltinTopicDcpsPublication
        from cyclonedds.core import InstanceState
        from cyclonedds.qos import Policy

        with self._peer_lock:
            if self._closed:  # a reader thread's last look after the link closed (at exit: _close_links_at_exit)
                return dict.fromkeys(self._topics, 0)
            if self._publications is None:
                self._publications = BuiltinDataReader(self._participant, BuiltinTopicDcpsPublication)
            return self._update_writers(InstanceState, Policy)

    def _update_writers(self, InstanceState, Policy) -> dict[str, int]:
        ours = {self.partition or ""}
        for sample in self._publications.take(N=256):
            info = sample.sample_info
            handle = info.instance_handle
            if info.instance_state != InstanceState.Alive or not info.valid_data:
                self._writers.pop(handle, None)
                continue
            if sample.topic_name not in self._topics or str(sample.key) == self._own_writer:
                continue
            partition = sample.qos[Policy.Partition] if sample.qos is not None else None
            theirs = set(partition.partitions) if partition is not None and partition.partitions else {""}
            if theirs & ours:
                self._writers[handle] = (sample.topic_name, str(sample.key))
        counts = dict.fromkeys(self._topics, 0)
        for topic, _ in self._writers.values():
            counts[topic] += 1
        return counts

    def _take_now(self):
        with self._io_lock:
            return [] if self._closed else self._take(self._reader._ref, self._depth)

    def close(self) -> None:
        # Entities are reclaimed with the participant; dropping our references is enough, and the
        # domain (with its interface binding) stays for the rest of the process.
        with self._io_lock:
            if self._closed:
                return
            self._closed = True
            _open_links.discard(self)
            self._waitset.detach(self._condition)
            del self._writer, self._reader, self._condition, self._waitset
            with self._peer_lock:  # not while peer_writers() reads discovery
                del self._participant, self._publications
