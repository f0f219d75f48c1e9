"""A place's set-down pose (stances.release_hold_poses) is solved from the arms as carried; where that warm
start leaves the hands more than 3 cm from where the box goes, it is solved again from the arms' default
pose and the better is kept; only when both fall short is the place refused. The IK is stood in for by a
hold() that reaches from one start and not from the other (a local minimum, as seen once in physics)."""

from __future__ import annotations

import numpy as np
import pytest

from g1_control.generator.goals import stances as st
from g1_control.generator.goals.poses import PosePlanner, flat_soles, stance_heading
from g1_control.robot import g1

LEGS = len(g1.LEG_JOINTS)


class Hold:
    """hold(): 5 cm short from a start whose arms are not the default ones, 0.5 cm from the default."""

    def __init__(self, reaches_from_default: bool = True):
        self.starts: list[np.ndarray] = []
        self.reaches_from_default = reaches_from_default

    def hold(self, q0, soles, targets, heading, shift, pelvis_z, lean):
        self.starts.append(q0.copy())
        default = np.allclose(q0[7 + LEGS:], g1.DEFAULT_Q_RAD[LEGS:])
        res = 0.005 if default and self.reaches_from_default else 0.05
        return st.HoldPose(q0.copy(), res, 0.0, 0.0, 0.0)


@pytest.fixture(scope="module")
def poses():
    return PosePlanner()


def _call(poses, monkeypatch, fake: Hold):
    monkeypatch.setattr(st, "stance_planner", lambda _p: fake)
    monkeypatch.setattr(poses, "stand", lambda q, *a, **k: q)
    q0 = poses.ik.nominal()
    q0[7 + g1.JOINT_INDEX["left_elbow_joint"]] = 1.4  # the arms as carried
    q0[7 + g1.JOINT_INDEX["right_elbow_joint"]] = 1.4
    soles = flat_soles(poses.ik, q0)
    pts = (np.zeros((2, 3)),) * 4
    return q0, st.release_hold_poses(poses, q0, soles, stance_heading(soles), pts, np.zeros(2), float(q0[2]),
                                     st.UPRIGHT, False, "planned")


def test_a_set_down_out_of_reach_from_the_carried_arms_is_solved_again_from_the_default_arms(poses, monkeypatch):
    fake = Hold()
    q0, (_, q_down, *_rest) = _call(poses, monkeypatch, fake)
    assert np.allclose(fake.starts[0], q0)  # first from the arms as carried
    assert np.allclose(q_down[7 + LEGS:], g1.DEFAULT_Q_RAD[LEGS:])  # kept: the retry's pose
    np.testing.assert_allclose(q_down[:7 + LEGS], q0[:7 + LEGS])  # the legs and base as they stand


def test_short_from_both_starts_the_place_is_refused(poses, monkeypatch):
    with pytest.raises(st.StanceRefused, match="the hands get only within 5.0 cm of where the box goes"):
        _call(poses, monkeypatch, Hold(reaches_from_default=False))
