"""The preflight's robot checks on a stand-in backend (no DDS): both joint limits and their tolerance,
non-finite joints, temperatures and battery, the peer check. Fast, so a mutation run can use it."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from deploy_test_helpers import LinkStats as _Stats
from deploy_test_helpers import standing_state, write_launch

from g1_control.deploy.preflight import FAIL, PASS, SKIP, Preflight
from g1_control.launch.schema import load_launch
from g1_control.robot import g1
from g1_control.types import RobotState


class _Link:
    def describe(self) -> str:
        return "stand-in link"


class FakeBackend:
    """A robot reporting `state` at 500 Hz with clean CRCs; `peers` as LinkBackend.peers() says."""

    sees_peers = True

    def __init__(self, state: RobotState, peers=(1, 1, 0), battery_v=None):
        self.state, self._peers, self.link = state, peers, _Link()
        if battery_v is not None:
            self.state.battery_v = battery_v
        self._calls = 0

    def wait_for_state(self, timeout_s):
        return self.state

    def read_state(self):
        self.state.tick += 1  # a robot's tick advances with every sample (a frozen one fails the preflight)
        return self.state

    def stats(self):
        self._calls += 1
        return _Stats(states_received=0 if self._calls == 1 else 10_000)

    def refresh_peers(self):
        pass

    def peers(self):
        return self._peers


@pytest.fixture(scope="module")
def launch(tmp_path_factory):
    path = write_launch(tmp_path_factory.mktemp("pf"), {"deploy": {"state_window_s": 0.01}})
    return load_launch(path)


_state = standing_state


def _run(launch, backend) -> Preflight:
    pf = Preflight()
    pf.check_robot(backend, launch, None)
    return pf


def _with_joint(name: str, value: float) -> RobotState:
    q = g1.DEFAULT_Q_RAD.copy()
    q[g1.JOINT_INDEX[name]] = value
    return _state(q_rad=q)


def test_a_healthy_robot_passes_every_robot_check(launch):
    pf = _run(launch, FakeBackend(_state()))
    for name in ("variant", "state_stream", "peers", "imu_upright", "joint_limits", "temperatures"):
        assert pf.results[name].status == PASS, pf.results[name]
    assert pf.results["battery"].status == SKIP


@pytest.mark.parametrize("side", ["lower", "upper"])
def test_a_joint_past_either_limit_beyond_the_tolerance_fails(launch, side):
    tol = launch.deploy.joint_limit_tolerance_rad
    j = g1.JOINT_INDEX["left_knee_joint"]
    value = g1.Q_MIN_RAD[j] - tol - 0.01 if side == "lower" else g1.Q_MAX_RAD[j] + tol + 0.01
    pf = _run(launch, FakeBackend(_with_joint("left_knee_joint", value)))
    assert pf.results["joint_limits"].status == FAIL
    assert pf.results["joint_limits"].reason.startswith(f"1 joints outside their limits: left_knee_joint {value:+.3f}")


@pytest.mark.parametrize("side", ["lower", "upper"])
def test_a_joint_within_the_tolerance_passes(launch, side):
    tol = launch.deploy.joint_limit_tolerance_rad
    j = g1.JOINT_INDEX["left_knee_joint"]
    value = g1.Q_MIN_RAD[j] - tol / 2 if side == "lower" else g1.Q_MAX_RAD[j] + tol / 2
    assert _run(launch, FakeBackend(_with_joint("left_knee_joint", value))).results["joint_limits"].status == PASS


def test_the_tolerance_is_the_configured_one(launch):
    """0.05 rad past the limit fails at the default 0.02 rad tolerance (a tenfold one would pass it)."""
    j = g1.JOINT_INDEX["left_hip_pitch_joint"]
    pf = _run(launch, FakeBackend(_with_joint("left_hip_pitch_joint", g1.Q_MAX_RAD[j] + 0.05)))
    assert pf.results["joint_limits"].status == FAIL


def test_a_nan_joint_fails_naming_it_and_cannot_be_overridden(launch):
    pf = Preflight(frozenset({"joint_limits", "state_stream"}))
    pf.check_robot(FakeBackend(_with_joint("right_elbow_joint", np.nan)), launch, None)
    result = pf.results["joint_limits"]
    assert result.status == FAIL and not result.overridden and result.blocks
    assert "right_elbow_joint reads nan" in result.reason
    assert pf.results["state_stream"].status == FAIL and "q_rad[right_elbow_joint] = nan" in \
        pf.results["state_stream"].reason


def test_a_nan_temperature_fails(launch):
    temps = np.full(29, 40.0)
    temps[7] = np.nan
    pf = _run(launch, FakeBackend(_state(motor_temperature_c=temps)))
    assert pf.results["temperatures"].status == FAIL and g1.JOINT_NAMES[7] in pf.results["temperatures"].reason


@pytest.mark.parametrize(("battery", "status"), [(48.0, PASS), (30.0, FAIL), (float("nan"), FAIL)])
def test_battery_voltage_when_reported(launch, battery, status):
    assert _run(launch, FakeBackend(_state(), battery_v=battery)).results["battery"].status == status


@pytest.mark.parametrize(("peers", "status", "text"), [
    ((1, 1, 0), PASS, "one publisher on rt/lowstate"),
    ((2, 2, 0), FAIL, "2 publishers on rt/lowstate"),
    ((1, 2, 0), FAIL, "2 publishers on rt/lowstate"),
    ((2, 1, 0), FAIL, "2 publishers on rt/lowstate"),
    ((1, 1, 1), FAIL, "other writer(s) of rt/lowcmd"),
    ((0, None, None), SKIP, "carries bytes, not writers"),
])
def test_the_peer_check(launch, peers, status, text):
    pf = _run(launch, FakeBackend(_state(), peers=peers))
    assert pf.results["peers"].status == status and text in pf.results["peers"].reason
    if status == FAIL:
        assert not pf.results["peers"].overridable


# -- every branch's exact words (the operator reads them), against a golden file ----------------------

GOLDEN = Path(__file__).with_name("preflight_golden.yaml")


class _CountingStats(FakeBackend):
    """A stream that is slow, corrupted or framed badly, as `rate`, `bad` etc. say."""

    def __init__(self, state, rate_ok=True, bad_crc=0, malformed=0, bad_frames=0, **kw):
        super().__init__(state, **kw)
        self.rate_ok, self.bad = rate_ok, (bad_crc, malformed, bad_frames)

    def stats(self):
        self._calls += 1
        if self._calls == 1:
            return _Stats()
        return _Stats(states_received=10_000_000 if self.rate_ok else 1, bad_crc=self.bad[0], malformed=self.bad[1],
                      bad_frames=self.bad[2])


class _Silent(FakeBackend):
    def wait_for_state(self, timeout_s):
        from g1_control.errors import RobotNotConnectedError

        raise RobotNotConnectedError("no valid LowState from the robot within 3.0 s on stand-in link")


def _scenarios():
    q5 = g1.DEFAULT_Q_RAD.copy()
    q5[:5] = g1.Q_MAX_RAD[:5] + 0.5
    nan5 = g1.DEFAULT_Q_RAD.copy()
    nan5[:5] = np.nan
    hot = np.full(29, 40.0)
    hot[12] = 75.0
    tilted = np.array([np.cos(0.25), np.sin(0.25), 0.0, 0.0])
    return {
        "healthy": (FakeBackend(_state()), None),
        "other_variant_with_policy": (FakeBackend(_state(mode_machine=4)), "g1_29dof"),
        "other_variant": (FakeBackend(_state(mode_machine=6)), None),
        "unknown_variant": (FakeBackend(_state(mode_machine=9)), None),
        "slow_stream": (_CountingStats(_state(), rate_ok=False), None),
        "bad_crc": (_CountingStats(_state(), bad_crc=2), None),
        "malformed": (_CountingStats(_state(), malformed=1), None),
        "bad_frames": (_CountingStats(_state(), bad_frames=3), None),
        "five_joints_out": (FakeBackend(_state(q_rad=q5)), None),
        "five_joints_nan": (FakeBackend(_state(q_rad=nan5)), None),
        "hot_motor": (FakeBackend(_state(motor_temperature_c=hot)), None),
        "tilted": (FakeBackend(_state(imu_quat_wxyz=tilted)), None),
        "battery_low": (FakeBackend(_state(), battery_v=30.0), None),
        "battery_ok": (FakeBackend(_state(), battery_v=48.0), None),
        "no_state": (_Silent(_state()), None),
        "two_publishers": (FakeBackend(_state(), peers=(2, 2, 1)), None),
        "other_commander": (FakeBackend(_state(), peers=(1, 1, 2)), None),
    }


def _normalized(pf: Preflight) -> dict:
    import re

    rows = {}
    for r in pf.as_dict():
        reason = re.sub(r"^\d+ Hz over \d+\.\d s", "<rate> Hz over <window> s", r["reason"])
        rows[r["name"]] = {"status": r["status"], "reason": reason, "overridable": r["overridable"]}
    return {"checks": rows, "refusal": str(pf.refusal()) if not pf.passed else None}


def test_every_robot_check_says_exactly_what_the_golden_file_says(launch):
    import os

    import yaml

    got = {}
    for name, (backend, policy_variant) in _scenarios().items():
        pf = Preflight()
        pf.check_robot(backend, launch, policy_variant)
        got[name] = _normalized(pf)
    if os.environ.get("G1_UPDATE_GOLDEN"):
        # Written, never compared in the same run: a rewritten golden file proves nothing until a
        # person has read its diff and a normal run compares against it.
        GOLDEN.write_text(yaml.safe_dump(got, sort_keys=True, width=300, allow_unicode=True))
        pytest.fail(f"{GOLDEN.name} rewritten (G1_UPDATE_GOLDEN): review its diff, then run without G1_UPDATE_GOLDEN")
    expected = yaml.safe_load(GOLDEN.read_text())
    assert sorted(got) == sorted(expected), "every scenario has its golden entry and vice versa"
    for name in got:
        assert got[name] == expected[name], name


def test_overrides_are_recorded_loudly_and_refused_where_not_allowed(caplog):
    import logging

    caplog.set_level(logging.ERROR, logger="g1_control.deploy")
    pf = Preflight(frozenset({"temperatures", "variant"}))
    assert not pf.record("temperatures", FAIL, "hot")
    assert pf.results["temperatures"].overridden and not pf.results["temperatures"].blocks
    assert not pf.record("variant", FAIL, "other robot", overridable=False)
    assert not pf.results["variant"].overridden and pf.results["variant"].blocks
    assert pf.results["variant"].reason == "other robot (--override variant refused: this failure cannot be overridden)"
    assert pf.record("battery", SKIP, "n/a") and pf.record("imu_upright", PASS, "ok")
    assert [r.getMessage() for r in caplog.records] == [
        "PREFLIGHT OVERRIDE: check 'temperatures' failed (hot) and is overridden by --override temperatures"]
    with pytest.raises(Exception, match="--override temp, warp: no such check; checks: launch_file, policy"):
        Preflight(frozenset({"warp", "temp"}))
    fresh = Preflight()
    assert all(r.status == "not run" and r.reason == "not run" for r in fresh.results.values())
    fresh.not_run(["dry_run"], "no policy")
    assert fresh.results["dry_run"].reason == "not run: no policy"
