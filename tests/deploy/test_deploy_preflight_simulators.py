"""The preflight's robot checks against Unitree's simulators, on a stand-in link (no DDS; the listening
window on a stand-in clock; mutation-run survivors and "no tests", issue 26): the hint that a stream
with crc, tick and mode_machine at 0 is unitree_mujoco and not a robot (on every check that can see
it: no state at all, a frozen tick, no G1 variant), and only on a unitree_dds link on loopback
without backend.simulator; with the profile, the state_stream row names what the host filled in and
the simulator's own rate limit (80 % of 200 Hz: 160 Hz passes, 159 fails), the variant row says
when mode_machine was assumed; a tick frozen over two samples fails, over one it cannot tell."""

from __future__ import annotations

import dataclasses
from types import SimpleNamespace

import pytest
from deploy_test_helpers import LinkStats as _Stats
from deploy_test_helpers import standing_state, write_launch

from g1_control.deploy import preflight as pf_module
from g1_control.deploy.preflight import FAIL, NOT_RUN, PASS, Preflight
from g1_control.errors import G1ControlError, RobotNotConnectedError
from g1_control.hardware.unitree.simulators import SIMULATORS, RejectedSample, UnsetFields
from g1_control.launch.schema import load_launch

HINT = ("; hint: the LowState_ on loopback carries {names} all 0, as Unitree's MuJoCo simulator (unitree_mujoco) "
        "publishes it: not a robot. To run against it, set backend.simulator: unitree_mujoco (loopback only; see "
        "g1_control/hardware/unitree/simulators.py)")
CRC_TICK_MODE = HINT.format(names="crc, tick and mode_machine")
TICK_MODE = HINT.format(names="tick and mode_machine")
NO_VARIANT = ("the robot reports mode_machine 0, which is no G1 variant this project knows (unknown G1 mode_machine "
              "0; known: 4 (g1_23dof), 5 (g1_29dof), 6 (g1_29dof_locked_waist)); check that the robot is a G1 and "
              "its firmware is supported")
NO_STATE = "no LowState within 2.5 s on stand-in link"
ROBOT_ROWS = ("variant", "peers", "imu_upright", "joint_limits", "temperatures", "battery")


class _Link:
    """A stand-in link: `received` states over the window (counted from a large start), the state's
    tick advancing by `tick_step` per read (0: frozen), what a simulator profile filled in."""

    def __init__(self, state=None, received=500, tick_step=1, unset=None, rejected=None, connected=True,
                 readable=True):
        self.state, self.tick_step = state, tick_step
        self.counters = [_Stats(states_received=1_000_000), _Stats(states_received=1_000_000 + received)]
        self.link = SimpleNamespace(describe=lambda: "stand-in link")
        self.sees_peers = False
        self.unset_fields, self.rejected_sample = unset, rejected
        self.connected, self.readable = connected, readable

    def wait_for_state(self, timeout_s):
        if not self.connected:
            raise RobotNotConnectedError(f"no LowState within {timeout_s} s on stand-in link")
        return self.state

    def read_state(self):
        if not self.readable:
            raise G1ControlError("no state received yet")
        self.state.tick += self.tick_step
        return self.state

    def stats(self):
        return self.counters.pop(0)


@pytest.fixture(autouse=True)
def one_second_window(monkeypatch):
    """The listening window is exactly 1.0 s on a stand-in clock: a rate is the count of states."""
    now = [100.0]
    monkeypatch.setattr(pf_module, "time", SimpleNamespace(monotonic=lambda: now[0],
                                                           sleep=lambda s: now.__setitem__(0, now[0] + s)))


@pytest.fixture(scope="module")
def launch(tmp_path_factory):
    """launch/sim2sim.yaml (unitree_dds on lo): a robot, or g1 sim-robot; no simulator profile."""
    path = write_launch(tmp_path_factory.mktemp("pfs"), {"deploy": {"state_window_s": 1.0, "min_state_rate_hz": 400},
                                                        "backend": {"connect_timeout_s": 2.5}})
    return load_launch(path)


@pytest.fixture(scope="module")
def simulator(tmp_path_factory):
    """The same with backend.simulator: unitree_mujoco."""
    path = write_launch(tmp_path_factory.mktemp("pfs"), {"deploy": {"state_window_s": 1.0, "min_state_rate_hz": 400},
                                                        "backend": {"connect_timeout_s": 2.5,
                                                                    "simulator": "unitree_mujoco"}})
    return load_launch(path)


def _backend(launch, **changes):
    return dataclasses.replace(launch, backend=dataclasses.replace(launch.backend, **changes))


def _check(launch, link) -> Preflight:
    pf = Preflight()
    pf.check_robot(link, launch, None)
    return pf


def _sim_state():
    """What unitree_mujoco publishes: tick and mode_machine 0."""
    state = standing_state(mode_machine=0)
    state.tick = 0
    return state


ZEROS = RejectedSample(crc=0, tick=0, mode_machine=0)


# -- no state at all ----------------------------------------------------------------------------------------
def test_no_state_with_a_dropped_zero_sample_on_loopback_hints_at_the_simulator(launch):
    pf = Preflight()
    assert pf.check_robot(_Link(connected=False, rejected=ZEROS), launch, None) is None
    r = pf.results["state_stream"]
    assert (r.status, r.overridable, r.reason) == (FAIL, False, NO_STATE + CRC_TICK_MODE)
    assert [(n, pf.results[n].status, pf.results[n].reason) for n in ROBOT_ROWS] == [
        (n, NOT_RUN, "not run: no robot state") for n in ROBOT_ROWS]


@pytest.mark.parametrize("sample", [RejectedSample(crc=0x1234, tick=0, mode_machine=0),
                                    RejectedSample(crc=0, tick=7, mode_machine=0),
                                    RejectedSample(crc=0, tick=0, mode_machine=5)])
def test_a_dropped_sample_with_any_field_set_is_no_simulator(launch, sample):
    r = _check(launch, _Link(connected=False, rejected=sample)).results["state_stream"]
    assert r.reason == NO_STATE


def test_no_hint_where_the_simulator_is_configured_or_the_link_is_no_dds_loopback(launch, simulator):
    for where in (simulator, _backend(launch, interface="eth0"), _backend(launch, type="can")):
        r = _check(where, _Link(connected=False, rejected=ZEROS)).results["state_stream"]
        assert (r.status, r.overridable, r.reason) == (FAIL, False, NO_STATE)


def test_no_state_and_no_dropped_sample_hints_from_the_last_state_if_there_is_one(launch):
    r = _check(launch, _Link(_sim_state(), connected=False, tick_step=0)).results["state_stream"]
    assert r.reason == NO_STATE + TICK_MODE
    r = _check(launch, _Link(connected=False, readable=False)).results["state_stream"]
    assert r.reason == NO_STATE
    robot = standing_state()  # mode_machine 5, tick 0
    r = _check(launch, _Link(robot, connected=False, tick_step=0)).results["state_stream"]
    assert r.reason == NO_STATE


# -- a stream without the profile: frozen tick, no variant ---------------------------------------------------
def test_the_simulators_stream_without_its_profile_fails_frozen_and_without_a_variant_with_the_hint(launch):
    pf = _check(launch, _Link(_sim_state(), tick_step=0))
    r = pf.results["state_stream"]
    assert (r.status, r.overridable) == (FAIL, False)
    assert r.reason == ("500 Hz over 1.0 s, 0 bad CRC, 0 malformed; tick frozen: 500 samples arrived in 1.0 s, every "
                        "one with tick 0: the robot's state publisher is stuck (the control loop would trip on 'tick "
                        "frozen' at once)" + TICK_MODE)
    r = pf.results["variant"]
    assert (r.status, r.overridable, r.reason) == (FAIL, False, NO_VARIANT + TICK_MODE)
    assert pf.results["imu_upright"].status == PASS  # the other checks still run: every fault is shown at once


def test_a_frozen_tick_cannot_be_overridden(launch):
    """The loop's tick-order check would damp on the first tick: an override would only start a damp."""
    pf = Preflight(overrides=frozenset({"state_stream"}))
    pf.check_robot(_Link(standing_state(), tick_step=0), launch, None)
    r = pf.results["state_stream"]
    assert (r.status, r.overridable) == (FAIL, False)
    assert r.reason.endswith("tick frozen' at once) (--override state_stream refused: this failure cannot be "
                             "overridden)")
    assert not pf.passed


def test_off_loopback_the_same_stream_fails_without_the_hint(launch):
    pf = _check(_backend(launch, interface="eth0"), _Link(_sim_state(), tick_step=0))
    assert pf.results["state_stream"].reason.endswith("(the control loop would trip on 'tick frozen' at once)")
    assert pf.results["variant"].reason == NO_VARIANT


def test_a_frozen_robot_tick_has_no_hint(launch):
    state = standing_state()
    state.tick = 41
    pf = _check(launch, _Link(state, tick_step=0))
    assert pf.results["state_stream"].reason == (
        "500 Hz over 1.0 s, 0 bad CRC, 0 malformed; tick frozen: 500 samples arrived in 1.0 s, every one with tick "
        "41: the robot's state publisher is stuck (the control loop would trip on 'tick frozen' at once)")
    assert pf.results["variant"].status == PASS


@pytest.mark.parametrize(("received", "frozen"), [(1, False), (2, True)])
def test_a_tick_is_frozen_only_over_two_samples_or_more(launch, received, frozen):
    slow = dataclasses.replace(launch, deploy=dataclasses.replace(launch.deploy, min_state_rate_hz=1.0))
    state = standing_state()
    state.tick = 9
    r = _check(slow, _Link(state, received=received, tick_step=0)).results["state_stream"]
    assert r.status == (FAIL if frozen else PASS), r.reason
    head = f"{received} Hz over 1.0 s, 0 bad CRC, 0 malformed"
    assert r.reason == (f"{head}; tick frozen: {received} samples arrived in 1.0 s, every one with tick 9: the robot's "
                        "state publisher is stuck (the control loop would trip on 'tick frozen' at once)"
                        if frozen else head)


# -- with backend.simulator: unitree_mujoco -----------------------------------------------------------------
def _filled(*fields) -> UnsetFields:
    unset = UnsetFields(SIMULATORS["unitree_mujoco"], mode_machine=5)
    unset.filled.update(fields)
    return unset


@pytest.mark.parametrize(("received", "status"), [(160, PASS), (159, FAIL)])
def test_the_simulator_is_held_to_80_percent_of_its_own_rate(simulator, received, status):
    state = standing_state()  # as the host hands it on: tick counted, mode_machine filled
    r = _check(simulator, _Link(state, received=received, unset=_filled("crc", "tick", "mode_machine"))).results[
        "state_stream"]
    assert r.status == status
    head = f"{received} Hz over 1.0 s, 0 bad CRC, 0 malformed"
    assert r.reason == (f"{head}; backend.simulator unitree_mujoco (200 Hz, robot needs 400): crc 0 accepted unchecked, "
                        "tick 0 counted by the host, mode_machine 0 read as 5" if status == PASS else
                        f"{head}; need >= 160 Hz on stand-in link: check the cable/switch and that nothing else loads "
                        "this host")


def test_the_variant_row_says_when_the_simulator_left_mode_machine_unset(simulator):
    pf = _check(simulator, _Link(standing_state(), unset=_filled("crc", "tick", "mode_machine")))
    assert pf.results["variant"].reason == ("mode_machine 5 (g1_29dof, 29 DoF) (left 0 by unitree_mujoco: the launch "
                                            "file's expected_variant assumed)")
    pf = _check(simulator, _Link(standing_state(), unset=_filled("crc", "tick")))
    assert (pf.results["variant"].status, pf.results["variant"].reason) == (PASS, "mode_machine 5 (g1_29dof, 29 DoF)")
    assert pf.results["state_stream"].reason == ("500 Hz over 1.0 s, 0 bad CRC, 0 malformed; backend.simulator "
                                                 "unitree_mujoco (200 Hz, robot needs 400): crc 0 accepted unchecked, "
                                                 "tick 0 counted by the host")


def test_a_simulator_that_sets_every_field_is_checked_as_a_robot(simulator):
    pf = _check(simulator, _Link(standing_state(), unset=_filled()))
    assert pf.results["state_stream"].reason == ("500 Hz over 1.0 s, 0 bad CRC, 0 malformed; backend.simulator "
                                                 "unitree_mujoco (200 Hz, robot needs 400): every field set, checked "
                                                 "as a robot's")
    assert pf.results["variant"].reason == "mode_machine 5 (g1_29dof, 29 DoF)"


def test_a_robot_is_held_to_the_launch_files_rate(launch):
    r = _check(launch, _Link(standing_state(), received=399)).results["state_stream"]
    assert r.status == FAIL and "need >= 400 Hz" in r.reason
    r = _check(launch, _Link(standing_state(), received=400)).results["state_stream"]
    assert (r.status, r.reason) == (PASS, "400 Hz over 1.0 s, 0 bad CRC, 0 malformed")
