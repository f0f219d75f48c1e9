"""GuardedHands: finger commands clamped like joint commands (limits, speed, gains, effort), and
damping (kp 0, kd > 0) on NaN, a stale, frozen or faulted hand. The link here records what it is
given; tests/trackers/test_grasp.py checks the same over DDS against the emulated hands."""

from __future__ import annotations

import numpy as np
import pytest

from g1_control.errors import SafetyConfigError
from g1_control.robot import dex3
from g1_control.safety.hands import GuardedHands, HandSafetyConfig
from g1_control.types import FingerCommand, FingerState


class Clock:
    def __init__(self) -> None:
        self.t = 100.0

    def __call__(self) -> float:
        return self.t


class RecordingLink:
    """Both hands at the open pose, fresh states stamped with the test clock."""

    sides = dex3.SIDES
    damping_kd = 0.05

    def __init__(self, clock: Clock):
        self.clock = clock
        self.sent: list[tuple[str, FingerCommand]] = []
        self.q = {s: dex3.hand_limits(s).open_rad.copy() for s in self.sides}
        self.state_age_s = 0.0
        self.unchanged_s = 0.0
        self.error = (0, 0)

    def write(self, side, command):
        self.sent.append((side, command.copy()))

    def read(self, side):
        return FingerState(q_rad=self.q[side].copy(), t_s=self.clock() - self.state_age_s, error=self.error)

    def damp(self, sides=None):
        for side in sides or self.sides:
            self.write(side, FingerCommand.damping(self.damping_kd))

    def last_change_s(self, side):
        return self.clock() - self.unchanged_s


@pytest.fixture
def rig():
    clock = Clock()
    link = RecordingLink(clock)
    return GuardedHands(link, clock=clock), link, clock


def _stiff(q) -> FingerCommand:
    return FingerCommand(q_rad=np.asarray(q, dtype=float), kp=np.full(7, 2.0), kd=np.full(7, 0.05))


def test_targets_stay_inside_the_urdf_limits_less_the_margin(rig):
    hands, link, clock = rig
    lim = dex3.hand_limits("right")
    hands.write("right", _stiff(link.q["right"]))
    clock.t += 10.0  # long enough for any ramp
    out = hands.write("right", _stiff(np.full(7, 5.0)))
    np.testing.assert_allclose(out.q_rad, lim.q_max_rad - 0.02)
    clock.t += 10.0
    out = hands.write("right", _stiff(np.full(7, -5.0)))
    np.testing.assert_allclose(out.q_rad, lim.q_min_rad + 0.02)
    assert link.sent[-1][1] is not out and np.array_equal(link.sent[-1][1].q_rad, out.q_rad)


def test_a_jump_becomes_a_ramp_from_the_measured_position(rig):
    hands, link, clock = rig
    lim = dex3.hand_limits("left")
    closed = lim.closed_rad
    link.q["left"] = (lim.open_rad + closed) / 2  # mid-travel, inside the margins
    first = hands.write("left", _stiff(closed))
    np.testing.assert_allclose(first.q_rad, link.q["left"])  # the first command starts where the hand is
    clock.t += 0.01
    second = hands.write("left", _stiff(closed))
    step = np.abs(second.q_rad - first.q_rad)
    assert np.max(step) == pytest.approx(0.03)  # 3 rad/s for 10 ms
    assert np.all(step <= 0.03 + 1e-12)


def test_gains_and_torque_are_capped(rig):
    hands, link, _ = rig
    cmd = FingerCommand(q_rad=link.q["right"], kp=np.full(7, 100.0), kd=np.full(7, 9.0), tau_nm=np.full(7, -10.0),
                        dq_radps=np.full(7, 50.0))
    out = hands.write("right", cmd)
    assert np.all(out.kp == 5.0) and np.all(out.kd == 0.5)
    np.testing.assert_allclose(out.tau_nm, -dex3.hand_limits("right").effort_nm)
    np.testing.assert_allclose(out.dq_radps, dex3.hand_limits("right").velocity_radps)


def test_negative_gains_are_raised_to_zero(rig):
    """A negative kp or kd would push a finger away from its target or feed its speed back: both are
    clamped to 0, never passed on."""
    hands, link, _ = rig
    cmd = FingerCommand(q_rad=link.q["left"], kp=np.full(7, -2.0), kd=np.full(7, -0.3))
    out = hands.write("left", cmd)
    assert np.all(out.kp == 0.0) and np.all(out.kd == 0.0)
    assert np.all(link.sent[-1][1].kd >= 0.0)


def test_nan_is_refused_and_both_hands_damp_until_reset(rig):
    hands, link, clock = rig
    hands.write("right", _stiff(link.q["right"]))
    bad = _stiff(link.q["right"])
    bad.q_rad[2] = np.nan
    out = hands.write("right", bad)
    assert out.is_damping
    assert hands.tripped == "right hand command is not finite (q_rad[thumb_2]); the fingers were damped"
    damped = {side for side, c in link.sent if c.is_damping}
    assert damped == {"left", "right"}
    assert all(c.is_finite() for _, c in link.sent)  # the NaN never reached the link
    n = len(link.sent)
    clock.t += 0.01
    assert hands.write("left", _stiff(link.q["left"])).is_damping  # latched
    assert len(link.sent) == n  # nothing new: the link keeps streaming the damping it was given
    hands.reset_trip()
    assert not hands.write("left", _stiff(link.q["left"])).is_damping


def test_a_hand_reading_nan_damps_and_no_nan_reaches_the_link(rig):
    """The first command ramps from the measured position: a NaN finger reading would make that
    target NaN (and every later one, each ramp step starting from the last). A hand that reads no
    number trips and damps; nothing that is not finite reaches the link."""
    hands, link, clock = rig
    link.q["left"][2] = np.nan
    out = hands.write("left", _stiff(dex3.hand_limits("left").open_rad))
    assert out.is_damping
    assert hands.tripped.startswith("the left hand reads no number (q_rad[thumb_2])")
    link.q["left"][2] = 0.0
    clock.t += 0.01
    assert hands.write("left", _stiff(dex3.hand_limits("left").open_rad)).is_damping  # latched
    assert link.sent and all(c.is_finite() for _, c in link.sent)


@pytest.mark.parametrize("fault, words", [
    ("stale", "the left hand's state is 0.30 s old (limit 0.25 s)"),
    ("frozen", "the left hand's state has not changed for 0.60 s (limit 0.50 s): frozen"),
    ("error", "the left hand reports error 0x4/0x0"),
])
def test_a_stale_frozen_or_faulted_hand_damps(rig, fault, words):
    hands, link, _ = rig
    assert not hands.write("left", _stiff(link.q["left"])).is_damping
    if fault == "stale":
        link.state_age_s = 0.3
    elif fault == "frozen":
        link.unchanged_s = 0.6
    else:
        link.error = (4, 0)
    assert hands.write("left", _stiff(link.q["left"])).is_damping
    assert hands.tripped is not None and hands.tripped.startswith(words)
    assert {side for side, c in link.sent[-2:] if c.is_damping} == {"left", "right"}


def test_config_refuses_nonsense():
    with pytest.raises(SafetyConfigError, match="HandSafetyConfig.max_kp is 0; it must be positive"):
        HandSafetyConfig(max_kp=0.0)
    with pytest.raises(SafetyConfigError, match="HandSafetyConfig.stale_state_s is nan"):
        HandSafetyConfig(stale_state_s=float("nan"))
