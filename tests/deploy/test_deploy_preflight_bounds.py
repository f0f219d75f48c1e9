"""The preflight's robot checks at their boundaries (mutation-run survivors, issue 16): each limit is
inclusive where the check says so, listings end in " ..." only past their length, the stream's
counters are differences over the window, a link that reports writers but no recent sender is still
judged, a backend that cannot see its peers is skipped. The listening window runs on a stand-in clock."""

from __future__ import annotations

import dataclasses
from types import SimpleNamespace

import numpy as np
import pytest
from deploy_test_helpers import LinkStats as _Stats
from deploy_test_helpers import standing_state, write_launch

from g1_control.deploy import preflight as pf_module
from g1_control.deploy.preflight import FAIL, PASS, SKIP, Preflight, nonfinite_fields
from g1_control.launch.schema import load_launch
from g1_control.robot import g1
from g1_control.rotations import tilt_rad
from g1_control.types import RobotState


class _Robot:
    """A stand-in robot link: `state`; transport counters `before` and `after` the window; peers."""

    def __init__(self, state, before=None, after=None, peers=(1, 1, 0), can_see_peers=True):
        self.state = state
        self.counters = [before or _Stats(), after or _Stats(states_received=500)]
        self._peers = peers
        self.link = SimpleNamespace(describe=lambda: "stand-in link")
        self.timeouts: list = []
        self.sees_peers = can_see_peers
        self.unset_fields = self.rejected_sample = None  # a robot, not one of Unitree's simulators

    def refresh_peers(self):
        assert self.sees_peers, "refresh_peers on a link that cannot see its peers"

    def wait_for_state(self, timeout_s):
        self.timeouts.append(timeout_s)
        return self.state

    def read_state(self):
        self.state.tick += 1  # a robot's tick advances with every sample (a frozen one fails the preflight)
        return self.state

    def stats(self):
        return self.counters.pop(0)

    def peers(self):
        return self._peers


@pytest.fixture(autouse=True)
def one_second_window(monkeypatch):
    """The listening window is exactly 1.0 s on a stand-in clock: a rate is the count of states."""
    now = [100.0]

    def sleep(s):
        now[0] += s

    monkeypatch.setattr(pf_module, "time", SimpleNamespace(monotonic=lambda: now[0], sleep=sleep))


@pytest.fixture(scope="module")
def launch(tmp_path_factory):
    path = write_launch(tmp_path_factory.mktemp("pfb"), {"deploy": {"state_window_s": 1.0, "min_state_rate_hz": 400},
                                                        "backend": {"connect_timeout_s": 2.5}})
    return load_launch(path)


_state = standing_state


def _check(launch, robot, **deploy) -> Preflight:
    if deploy:
        launch = dataclasses.replace(launch, deploy=dataclasses.replace(launch.deploy, **deploy))
    pf = Preflight()
    pf.check_robot(robot, launch, None)
    return pf


def test_the_state_is_awaited_for_the_launch_files_connect_timeout(launch):
    robot = _Robot(_state())
    _check(launch, robot)
    assert robot.timeouts == [2.5]


@pytest.mark.parametrize(("received", "status"), [(400, PASS), (399, FAIL)])
def test_the_state_rate_limit_is_inclusive(launch, received, status):
    before = _Stats(states_received=1_000_000, bad_crc=7, malformed=3, bad_frames=2)
    after = _Stats(states_received=1_000_000 + received, bad_crc=7, malformed=3, bad_frames=2)
    r = _check(launch, _Robot(_state(), before, after)).results["state_stream"]
    assert r.status == status, r.reason
    assert r.reason.startswith(f"{received} Hz over 1.0 s, 0 bad CRC, 0 malformed")


@pytest.mark.parametrize(("field", "words"), [("bad_crc", "2 bad CRC, 0 malformed"), ("malformed", "0 bad CRC, 2 malformed"),
                                              ("bad_frames", "0 bad CRC, 0 malformed, 2 bad frames")])
def test_stream_faults_are_counted_over_the_window(launch, field, words):
    before = _Stats(states_received=5000, bad_crc=4, malformed=4, bad_frames=4)
    after = dataclasses.replace(before, states_received=5600, **{field: 6})
    r = _check(launch, _Robot(_state(), before, after)).results["state_stream"]
    assert r.status == FAIL and r.reason.startswith(f"600 Hz over 1.0 s, {words}; corrupted samples on stand-in link")


def _nonfinite_state(n: int) -> RobotState:
    state = _state()
    for i in range(n):
        state.dq_radps[i] = np.nan
    return state


@pytest.mark.parametrize("n", [4, 5])
def test_nonfinite_fields_are_listed_four_at_most(launch, n):
    r = _check(launch, _Robot(_nonfinite_state(n))).results["state_stream"]
    listed = ", ".join(f"dq_radps[{g1.JOINT_NAMES[i]}] = nan" for i in range(4))
    assert r.reason == (f"500 Hz over 1.0 s, 0 bad CRC, 0 malformed; the robot reports values that are not finite "
                        f"numbers: {listed}{' ...' if n > 4 else ''}: a sensor or its decoding is broken")


def test_nonfinite_fields_name_joints_or_indices():
    state = _state()
    state.imu_gyro_radps[1] = np.inf
    state.q_rad[2] = np.nan
    assert nonfinite_fields(state) == [f"q_rad[{g1.JOINT_NAMES[2]}] = nan", "imu_gyro_radps[1] = inf"]


@pytest.mark.parametrize("n", [3, 4])
def test_joints_without_a_number_are_listed_three_at_most(launch, n):
    q = g1.DEFAULT_Q_RAD.copy()
    q[:n] = np.nan
    r = _check(launch, _Robot(_state(q_rad=q))).results["joint_limits"]
    listed = ", ".join(f"{g1.JOINT_NAMES[j]} reads nan" for j in range(3))
    assert r.reason == (f"{n} joints read no number: {listed}{' ...' if n > 3 else ''}; the encoder or its decoding is "
                        "broken: do not start")


@pytest.mark.parametrize("n", [3, 4])
def test_joints_outside_their_limits_are_listed_three_at_most(launch, n):
    q = g1.DEFAULT_Q_RAD.copy()
    q[:n] = g1.Q_MAX_RAD[:n] + 0.5
    r = _check(launch, _Robot(_state(q_rad=q))).results["joint_limits"]
    listed = ", ".join(f"{g1.JOINT_NAMES[j]} {q[j]:+.3f} rad [{g1.Q_MIN_RAD[j]:+.3f}, {g1.Q_MAX_RAD[j]:+.3f}]"
                       for j in range(3))
    assert r.reason == (f"{n} joints outside their limits: {listed}{' ...' if n > 3 else ''}; move them back by hand "
                        "with the motors off")


@pytest.mark.parametrize("side", ["min", "max"])
def test_a_joint_exactly_at_its_limit_passes(launch, side):
    q = g1.DEFAULT_Q_RAD.copy()
    knee = g1.JOINT_INDEX["left_knee_joint"]
    q[knee] = (g1.Q_MIN_RAD if side == "min" else g1.Q_MAX_RAD)[knee]
    assert _check(launch, _Robot(_state(q_rad=q)), joint_limit_tolerance_rad=0.0).results["joint_limits"].status == PASS


def test_the_tilt_limit_is_inclusive_and_a_nan_quaternion_fails(launch):
    quat = np.array([np.cos(0.1), np.sin(0.1), 0.0, 0.0])
    limit = tilt_rad(quat)
    r = _check(launch, _Robot(_state(imu_quat_wxyz=quat)), max_start_tilt_rad=limit).results["imu_upright"]
    assert r.status == PASS and r.reason == f"tilt {limit:.3f} rad (limit {limit:.2f})"
    r = _check(launch, _Robot(_state(imu_quat_wxyz=np.array([np.nan, 0.0, 0.0, 0.0])))).results["imu_upright"]
    assert r.status == FAIL
    assert r.reason == "tilt nan rad > 0.30: stand the robot up or hang it on its gantry before starting"


def test_a_motor_exactly_at_the_start_temperature_limit_fails(launch):
    temps = np.full(29, 40.0)
    temps[4] = 70.0
    r = _check(launch, _Robot(_state(motor_temperature_c=temps))).results["temperatures"]
    assert r.status == FAIL and r.reason.startswith(f"{g1.JOINT_NAMES[4]} motor at 70 °C (limit 70 °C)")
    temps[4] = 69.9
    assert _check(launch, _Robot(_state(motor_temperature_c=temps))).results["temperatures"].status == PASS


def test_a_battery_exactly_at_its_limit_passes(launch):
    state = _state()
    state.battery_v = 40.0
    r = _check(launch, _Robot(state)).results["battery"]
    assert (r.status, r.reason) == (PASS, "battery at 40.0 V")


@pytest.mark.parametrize(("peers", "status"), [((0, 2, 0), FAIL), ((1, None, 0), PASS), ((0, 0, 0), PASS),
                                               ((2, None, 0), FAIL)])
def test_peers_are_judged_from_writers_or_recent_senders(launch, peers, status):
    r = _check(launch, _Robot(_state(), peers=peers)).results["peers"]
    assert r.status == status, r.reason


def test_peer_skips_say_why(launch):
    r = _check(launch, _Robot(_state(), peers=(0, None, None))).results["peers"]
    assert (r.status, r.reason) == (SKIP, "stand-in link carries bytes, not writers: a second sender shows only as a "
                                          "tick running backwards, which trips the run")
    r = _check(launch, _Robot(_state(), can_see_peers=False)).results["peers"]
    assert (r.status, r.reason) == (SKIP, "this backend cannot see its peers")


def test_the_refusal_lists_every_overridable_failure():
    pf = Preflight()
    pf.record("temperatures", FAIL, "hot")
    pf.record("battery", FAIL, "low")
    assert str(pf.refusal()).endswith("(overridable here: temperatures, battery)")
