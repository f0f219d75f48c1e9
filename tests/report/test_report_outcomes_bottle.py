"""report/outcomes.py judges a bottle's goals (one hand) from ground truth as it judges a box's (two):
hand-built arrays with known answers."""

from __future__ import annotations

import numpy as np

from g1_control.report.outcomes import judge_goal, outcome_line


def _arrays(n: int = 101):
    t = np.linspace(0.0, 10.0, n)
    hands = np.zeros((n, 2, 3))
    hands[:, 0, 2] = 0.7 - 0.05 * t  # the left hand (idle) sinks 0.5 m: not the holding hand
    hands[:, 1, 2] = 0.9 + np.clip(t - 4.0, 0.0, 1.0) * 0.1  # the right hand lifts 0.1 m over 4-5 s
    bottle = np.zeros((n, 7))
    bottle[:, 3] = 1.0
    bottle[:, 2] = 0.83 + np.clip(t - 4.0, 0.0, 1.0) * 0.1 - np.clip(t - 6.0, 0.0, 1.0) * 0.004  # slips 4 mm
    bottle[:, :2] = (0.43, -0.16)
    return {"t_s": t, "hands_w_m": hands, "bottle_bottle": bottle}


def test_a_bottle_pick_is_judged_against_the_hand_that_holds_it():
    info = {"kind": "pick", "describe": "pick bottle", "status": "reached", "start_s": 2.0, "end_s": 8.0,
            "bottle": "bottle", "hand": "right", "object_start_w_m": [0.43, -0.16, 0.83], "held_from_s": 5.0,
            "lift_m": 0.1}
    out = judge_goal("g", info, _arrays())
    assert out["object_kind"] == "bottle"
    assert abs(out["slip_m"] - 0.004) < 1e-6  # against the right hand: the idle left one sank 0.5 m
    assert 0.09 < out["box_rise_m"] < 0.1 and not out["dropped"]
    assert "bottle lifted" in outcome_line(out)


def test_a_bottle_place_is_judged_by_where_its_centre_rests_and_its_tilt():
    a = _arrays()
    a["bottle_bottle"][-1, :3] = (0.45, -0.01, 0.83)
    tilt = np.radians(8.0)
    a["bottle_bottle"][-1, 3:] = (np.cos(tilt / 2), np.sin(tilt / 2), 0.0, 0.0)
    info = {"kind": "place", "describe": "place bottle", "status": "reached", "start_s": 0.0, "end_s": 10.0,
            "bottle": "bottle", "hand": "right", "target_w_m": [0.43, -0.01, 0.83], "released_s": 9.0}
    out = judge_goal("g", info, a)
    assert abs(out["place_error_xy_m"] - 0.02) < 1e-9 and abs(out["box_tilt_deg"] - 8.0) < 1e-6
    assert "bottle 2.0 cm from where it was to go" in outcome_line(out)
