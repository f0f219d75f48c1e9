"""Release of the G1's built-in motion service before low-level control.

While Unitree's own locomotion controller runs, it streams its own rt/lowcmd and the robot mixes
or ignores ours. Unitree's motion-switcher service (an RPC over DDS: Request_/Response_ on
rt/api/motion_switcher/{request,response}) reports the active controller (CheckMode, api 1001,
JSON data with a "name" that is empty once none is active) and releases it (ReleaseMode, api 1003).
Operators who instead put the robot in debug mode with the remote skip this (--no-release).

MotionServiceEmulator answers the same calls for the robot emulator and for tests.
"""

from __future__ import annotations

import itertools
import json
import logging
import threading
import time

from g1_control.errors import MotionServiceError
from g1_control.hardware.links.dds import DdsEntities

log = logging.getLogger(__name__)

SERVICE_NAME = "motion_switcher"
REQUEST_TOPIC = f"rt/api/{SERVICE_NAME}/request"
RESPONSE_TOPIC = f"rt/api/{SERVICE_NAME}/response"
API_CHECK_MODE = 1001
API_SELECT_MODE = 1002
API_RELEASE_MODE = 1003
STATUS_OK = 0

_ids = itertools.count(time.monotonic_ns())


def _endpoints(participant, partition: str | None, serving: bool) -> DdsEntities:
    """The request/response writer ("writer") and reader ("reader"), made under the process-wide DDS
    entity lock (hardware/links/dds.py: DdsEntities) on `participant`, which the caller owns."""
    from cyclonedds.pub import DataWriter, Publisher
    from cyclonedds.qos import Policy, Qos
    from cyclonedds.sub import DataReader, Subscriber
    from cyclonedds.topic import Topic

    from g1_control.hardware.unitree.idl import Request_, Response_

    entities = DdsEntities()
    with entities.lock():
        requests = Topic(participant, REQUEST_TOPIC, Request_)
        responses = Topic(participant, RESPONSE_TOPIC, Response_)
        group = Qos(Policy.Partition([partition])) if partition else None
        reliable = Qos(Policy.Reliability.Reliable(1_000_000_000), Policy.History.KeepLast(16))
        out_topic, in_topic = (responses, requests) if serving else (requests, responses)
        # The sample type depends on the side (requests out and responses in, or the reverse).
        entities.add("writer", DataWriter(Publisher(participant, qos=group), out_topic, qos=reliable))
        entities.add("reader", DataReader(Subscriber(participant, qos=group), in_topic, qos=reliable))
    return entities


class MotionServiceClient:
    def __init__(self, participant, partition: str | None = None, timeout_s: float = 1.0):
        self._dds = _endpoints(participant, partition, serving=False)
        self.timeout_s = timeout_s

    def close(self) -> None:
        """Delete the client's writer and reader (under the process-wide DDS entity lock)."""
        self._dds.close()

    def call(self, api_id: int, parameter: str = "") -> tuple[int, str]:
        from g1_control.hardware.unitree.idl import (
            Request_,
            RequestHeader_,
            RequestIdentity_,
            RequestLease_,
            RequestPolicy_,
        )

        request_id = next(_ids)
        header = RequestHeader_(RequestIdentity_(request_id, api_id), RequestLease_(0), RequestPolicy_(0, False))
        deadline = time.monotonic() + self.timeout_s
        # The first request may go out before discovery has matched the service; resend until
        # a response arrives or the time is up.
        while time.monotonic() < deadline:
            if not self._dds.write("writer", Request_(header, parameter, [])):
                raise MotionServiceError(f"motion service call (api {api_id}) on a closed client")
            resend_at = min(deadline, time.monotonic() + 0.1)
            while time.monotonic() < resend_at:
                for response in self._dds.take("reader", 16):
                    if getattr(response, "header", None) and response.header.identity.id == request_id:
                        return int(response.header.status.code), response.data
                time.sleep(0.005)
        raise MotionServiceError(
            f"the robot's motion service did not answer api {api_id} within {self.timeout_s:.1f} s; "
            "is the robot on this interface/domain? If you put it in debug mode with the remote instead, "
            "skip the release (--no-release-motion-service)"
        )

    def check_mode(self) -> str:
        """Name of the active built-in controller; '' when none is active."""
        code, data = self.call(API_CHECK_MODE)
        if code != STATUS_OK:
            raise MotionServiceError(f"motion service CheckMode failed with status {code}")
        try:
            return str(json.loads(data or "{}").get("name", ""))
        except (json.JSONDecodeError, AttributeError):
            raise MotionServiceError(f"motion service CheckMode answered unreadable data {data!r}") from None

    def release_mode(self) -> None:
        code, _ = self.call(API_RELEASE_MODE)
        if code != STATUS_OK:
            raise MotionServiceError(f"motion service ReleaseMode failed with status {code}")


def release_motion_service(participant, partition: str | None = None, timeout_s: float = 5.0) -> list[str]:
    """Release every active built-in controller; return the names released (in order)."""
    client = MotionServiceClient(participant, partition, timeout_s=min(timeout_s, 2.0))
    released: list[str] = []
    deadline = time.monotonic() + timeout_s
    try:
        while (name := client.check_mode()):
            if time.monotonic() > deadline:
                raise MotionServiceError(
                    f"the robot's motion service still runs '{name}' after {timeout_s:.0f} s of release requests; "
                    "stop it from the app or put the robot in debug mode with the remote")
            log.info("releasing the robot's built-in controller '%s'", name)
            client.release_mode()
            released.append(name)
            time.sleep(0.2)
    finally:
        client.close()
    return released


class MotionServiceEmulator:
    """Answers CheckMode/ReleaseMode/SelectMode like the robot's service (for the emulator and tests)."""

    def __init__(self, participant, partition: str | None = None, active_mode: str = "ai",
                 on_change=None):
        """on_change(active_mode) is called whenever a call changes the active mode."""
        self._dds = _endpoints(participant, partition, serving=True)
        self.active_mode = active_mode
        self.on_change = on_change
        self.calls: list[int] = []
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._serve, name="motion-service", daemon=True)
        self._thread.start()

    def _serve(self) -> None:
        from g1_control.hardware.unitree.idl import Response_, ResponseHeader_, ResponseStatus_

        while not self._stop.wait(0.005):
            for request in self._dds.take("reader", 16):  # [] once closed
                if not getattr(request, "header", None):
                    continue
                api_id = int(request.header.identity.api_id)
                self.calls.append(api_id)
                code, data = STATUS_OK, ""
                before = self.active_mode
                if api_id == API_CHECK_MODE:
                    data = json.dumps({"form": "0", "name": self.active_mode})
                elif api_id == API_RELEASE_MODE:
                    self.active_mode = ""
                elif api_id == API_SELECT_MODE:
                    self.active_mode = request.parameter
                else:
                    code = 3203  # Unitree RPC: API not implemented by the server
                if self.active_mode != before and self.on_change is not None:
                    self.on_change(self.active_mode)
                header = ResponseHeader_(request.header.identity, ResponseStatus_(code))
                self._dds.write("writer", Response_(header, data, []))  # dropped once closed

    def close(self) -> None:
        """Stop serving and delete the endpoints under the process-wide DDS entity lock: a serving thread
        that outlives the join finds them closed (no take, no write) and ends at its next wait."""
        self._stop.set()
        self._thread.join(timeout=2.0)
        self._dds.close()
