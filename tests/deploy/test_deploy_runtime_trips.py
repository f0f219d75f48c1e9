"""The runtime trips `g1 deploy` relies on, each through the deploy's own control loop over real DDS
on loopback (lo, domain 1, a partition per test) against the robot emulator (MockG1 motors), each
with no other symptom that could trip in its place:

- the robot collapsing: the legs report a deep squat with the IMU upright, which only the
  estimator's pelvis height (leg kinematics) shows -> a fall, "pelvis at ... m";
- a CRC burst: 10 LowState_ with a wrong CRC (20 ms), too short to make the state stale -> crc_burst;
- a foreign peer that sends nothing: a second writer of rt/lowstate or of rt/lowcmd that only DDS
  discovery sees (no tick, mode_machine or contents to give it away) -> foreign_peer.

Each test requires the specific trip (its typed kind and its reason), damping on the wire and a
faulted deploy."""

from __future__ import annotations

import threading
import time

import pytest
from deploy_test_helpers import write_launch

from g1_control.deploy.session import DeployOptions, deploy

pytestmark = pytest.mark.timing

CONTROL_S = 3.0
"""Control time of each deploy: a deploy whose trip did not fire ends 'control time over' (planned)."""


def _deploy_and_inject(tmp_path, partition, mock_robot, inject, delay_s: float = 0.5):
    """A --yes deploy (CONTROL_S of control) to an emulated robot; `inject(robot)` runs `delay_s` into
    control. Returns (robot, report, the tripping safety event as the report lists it)."""
    robot = mock_robot().start()
    control = threading.Event()
    lines: list[str] = []

    def later() -> None:
        time.sleep(delay_s)
        inject(robot)

    def say(line: str) -> None:
        lines.append(line)
        if "hold -> control" in line and not control.is_set():
            control.set()
            threading.Thread(target=later, daemon=True).start()

    launch = write_launch(tmp_path, {"deploy": {"state_window_s": 0.3, "input_check_s": 0.1}})
    report = deploy(launch, DeployOptions(yes=True, partition=partition, duration_s=CONTROL_S, out_root=tmp_path),
                    say=say)
    time.sleep(0.2)
    print("\n" + "\n".join(lines))
    assert control.is_set(), "the deploy never reached control"
    trips = [e for e in report.safety_events if e["trips"]]
    assert len(trips) == 1, report.safety_events
    return robot, report, trips[0]


def test_a_collapse_seen_only_by_the_estimators_pelvis_height_is_a_fall(tmp_path, partition, mock_robot):
    robot, report, trip = _deploy_and_inject(tmp_path, partition, mock_robot, lambda r: r.inject("collapse"))
    assert trip["kind"] == "fall", f"ended by {trip['kind']}: {trip['detail']} (expected a fall)"
    assert trip["detail"].startswith("pelvis at 0.3") and "(limit 0.40)" in trip["detail"], trip["detail"]
    assert report.fault and report.end_reason == trip["detail"]
    assert report.sequence[-1] == "damping"
    assert robot.report()["last_command_is_damping"] is True


def test_a_crc_burst_through_the_deploys_loop_trips_crc_burst(tmp_path, partition, mock_robot):
    robot, report, trip = _deploy_and_inject(tmp_path, partition, mock_robot, lambda r: r.inject("crc_burst"))
    assert trip["kind"] == "crc_burst", f"ended by {trip['kind']}: {trip['detail']} (expected crc_burst)"
    assert trip["detail"].startswith("5 bad-CRC states within 100 ms"), trip["detail"]
    assert report.fault and report.link["bad_crc"] == 10, report.link
    assert robot.report()["last_command_is_damping"] is True


def test_a_lone_bad_crc_does_not_trip(tmp_path, partition, mock_robot):
    """The counterpart: one bad state is counted, not a burst; the deploy runs to its end as planned."""
    def one_bad(robot) -> None:
        robot.endpoint.corrupt_next_states = 1

    robot = mock_robot().start()
    control = threading.Event()

    def say(line: str) -> None:
        if "hold -> control" in line and not control.is_set():
            control.set()
            threading.Timer(0.5, one_bad, (robot,)).start()

    launch = write_launch(tmp_path, {"deploy": {"state_window_s": 0.3, "input_check_s": 0.1}})
    report = deploy(launch, DeployOptions(yes=True, partition=partition, duration_s=1.5, out_root=tmp_path), say=say)
    assert report.link["bad_crc"] == 1 and not report.fault, (report.end_reason, report.link)
    assert report.end_reason.startswith("control time over")


@pytest.mark.parametrize("role, reason", [("robot", "2 publishers on rt/lowstate"),
                                          ("host", "1 other writer of rt/lowcmd")])
def test_a_silent_foreign_peer_trips_foreign_peer(tmp_path, partition, mock_robot, role, reason):
    """A second participant with a writer on the robot's topic that never sends: nothing but DDS
    discovery shows it (role robot: a writer of rt/lowstate; role host: a writer of rt/lowcmd)."""
    from g1_control.hardware.links.dds import DdsLink

    peers: list[DdsLink] = []
    try:
        robot, report, trip = _deploy_and_inject(
            tmp_path, partition, mock_robot, lambda r: peers.append(DdsLink(role, "lo", 1, partition=partition)))
    finally:
        for link in peers:
            link.close()
    assert peers, "the foreign peer was never created"
    assert trip["kind"] == "foreign_peer", f"ended by {trip['kind']}: {trip['detail']} (expected foreign_peer)"
    assert trip["detail"].startswith(reason), trip["detail"]
    assert report.fault and report.link["bad_crc"] == 0
    assert robot.report()["last_command_is_damping"] is True
