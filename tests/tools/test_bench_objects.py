"""g1 bench objects without physics: scenes drawn from (seed, index) alone and within the stated
ranges, and the ground-truth judge (a box placed, one dropped, one never lifted, a fall)."""

import math

import numpy as np

from g1_control.tools.bench_objects import (
    CARRY_BOX_SIDE_M,
    CARRY_DISTANCE_M,
    CARRY_HEIGHT_M,
    CARRY_MASS_KG,
    HEIGHT_BUCKETS_M,
    _why,
    draw_scene,
    height_bucket,
    judge,
    refusal_reason,
    refusal_table,
    summary,
)


def test_scenes_are_a_function_of_seed_and_index_within_the_ranges():
    a, b = draw_scene(3, 4), draw_scene(3, 4)
    assert a["scene"] == b["scene"] and a["target_xyz_m"] == b["target_xyz_m"]
    assert draw_scene(3, 5)["scene"] != a["scene"]
    buckets = set()
    for i in range(24):
        d = draw_scene(11, i)
        box = d["scene"].boxes[0]
        assert all(0.15 <= s <= 0.45 for s in box.size_m) and 0.2 <= box.mass_kg <= 6.0
        assert height_bucket(d["source"]["height_m"]) == d["source"]["bucket"]
        lo, hi = HEIGHT_BUCKETS_M[d["target"]["bucket"]]
        assert lo <= d["target"]["height_m"] <= hi
        d["scene"].validate("scene")
        buckets.add(d["source"]["bucket"])
    assert buckets == set(HEIGHT_BUCKETS_M)


def test_the_objects_scenes_are_those_earlier_stops_measured():
    """Seeds keep their scenes across changes to the drawing (--carry draws from its own stream): two
    draws of seed 90 as they were when its figures were taken (stop 50)."""
    a, b = draw_scene(90, 0), draw_scene(90, 1)
    assert a["source"]["height_m"] == 0.0 and math.isclose(a["mass_kg"], 2.21878693986439)
    np.testing.assert_allclose(a["target_xyz_m"], [1.5938461491343041, 0.7681383877961814, 0.9839207852635277])
    assert math.isclose(b["source"]["height_m"], 0.8889167249457033) and math.isclose(b["mass_kg"], 4.643787007410345)
    np.testing.assert_allclose(b["target_xyz_m"], [0.7393644711212342, 1.7758994675607502, 0.40120755870346264])


def test_carry_scenes_are_two_tables_3_to_5_m_apart_within_the_carry_ranges():
    assert draw_scene(3, 4, carry=True)["scene"] == draw_scene(3, 4, carry=True)["scene"]
    assert draw_scene(3, 4, carry=True)["scene"] != draw_scene(3, 4)["scene"]
    far = []
    for i in range(30):
        d = draw_scene(12, i, carry=True)
        scene = d["scene"]
        scene.validate("scene")
        box = scene.boxes[0]
        assert len(scene.tables) == 2 and box.stands_on == "table_a"
        assert all(CARRY_BOX_SIDE_M[0] <= s <= CARRY_BOX_SIDE_M[1] for s in box.size_m)
        assert CARRY_MASS_KG[0] <= box.mass_kg <= CARRY_MASS_KG[1]
        for t in scene.tables:
            assert CARRY_HEIGHT_M[0] <= t.height_m <= CARRY_HEIGHT_M[1]
        target = np.asarray(d["target_xyz_m"])
        assert scene.tables[1].contains_xy(target[:2]) and math.isclose(target[2], scene.tables[1].height_m + box.size_m[2] / 2)
        moved = float(np.hypot(*(target[:2] - np.asarray(box.xy_m))))
        assert math.isclose(moved, d["carry_m"])
        assert CARRY_DISTANCE_M[0] <= moved <= CARRY_DISTANCE_M[1] + 0.3  # the edges this far apart, then inset
        far.append(moved)
    assert max(far) - min(far) > 1.0  # drawn over the range, not one distance


def _arrays(box_z, hands_z, final_xy, tilt_rad=0.0):
    n = len(box_z)
    t = np.arange(n) * 0.1
    box = np.zeros((n, 7))
    box[:, 2] = box_z
    box[:, 3] = 1.0
    box[-1, :2] = final_xy
    box[-1, 3:7] = [math.cos(tilt_rad / 2), math.sin(tilt_rad / 2), 0.0, 0.0]
    hands = np.zeros((n, 2, 3))
    hands[:, :, 2] = np.asarray(hands_z)[:, None]
    return {"t_s": t, "box_box": box, "hands_w_m": hands}


DRAWN = {"target_xyz_m": [1.0, 1.0, 0.2], "source": {"bucket": "floor", "height_m": 0.0},
         "target": {"bucket": "low", "height_m": 0.05}, "mass_kg": 4.0, "size_m": [0.3, 0.3, 0.3], "box_yaw_deg": 0.0}
INFO = {"g0": {"kind": "pick", "status": "reached", "end_s": 0.45}, "g1": {"kind": "place", "status": "reached",
                                                                          "released_s": 0.85}}


def test_judge_a_carried_and_placed_box_succeeds():
    z = [0.15, 0.15, 0.2, 0.3, 0.3, 0.3, 0.3, 0.3, 0.25, 0.2, 0.2]
    hands = [0.5, 0.3, 0.2, 0.3, 0.3, 0.3, 0.3, 0.3, 0.25, 0.2, 0.3]
    r = judge(DRAWN, _arrays(z, hands, [1.03, 1.0]), INFO, {}, 0.7, False, index=0)
    assert r["success"] and r["lifted"] and r["held"] and r["placed"] and not r["dropped"]
    assert r["weight"] == "heavy" and abs(r["place_error_xy_m"] - 0.03) < 1e-9
    assert summary([r])["from floor"] == {"success": 1, "trials": 1}


def test_judge_sees_a_drop_a_tilt_a_miss_and_a_fall():
    z = [0.15, 0.15, 0.2, 0.3, 0.3, 0.15, 0.15, 0.15, 0.15, 0.2, 0.2]  # fell out of the hands at 0.5 s
    hands = [0.5, 0.3, 0.2, 0.3, 0.3, 0.3, 0.3, 0.3, 0.3, 0.3, 0.3]
    r = judge(DRAWN, _arrays(z, hands, [1.0, 1.0]), INFO, {}, 0.7, False, index=0)
    assert r["dropped"] and not r["success"]
    tilted = judge(DRAWN, _arrays([0.15, 0.3, 0.3, 0.2], [0.3, 0.3, 0.3, 0.2], [1.0, 1.0], tilt_rad=0.5),
                   {"g1": {"kind": "place", "status": "reached"}}, {}, 0.7, False, index=0)
    assert not tilted["upright"] and not tilted["success"]
    missed = judge(DRAWN, _arrays([0.15, 0.3, 0.3, 0.2], [0.3, 0.3, 0.3, 0.2], [1.2, 1.0]), {}, {}, 0.7, False,
                   index=0)
    assert not missed["placed"]
    fell = judge(DRAWN, _arrays([0.15, 0.3, 0.3, 0.2], [0.3, 0.3, 0.3, 0.2], [1.0, 1.0]), {}, {}, 0.25, False,
                 index=0)
    assert fell["fell"] and not fell["success"]
    refused = judge(DRAWN, _arrays([0.15] * 4, [0.5] * 4, [3.0, 0.0]),
                    {"g0": {"kind": "pick", "status": "failed"}}, {"g0": "no stance can pick it up"}, 0.7, False,
                    index=0)
    assert refused["refused"] == ["pick: no stance can pick it up"] and not refused["lifted"]


def test_judge_a_box_set_back_by_a_failed_pick_is_not_a_drop():
    """A pick whose box did not come up with the hands sets it back down and opens the hands
    (handling.pick's lift check): the hands leaving it after that is not a drop; sinking out of
    the hands before the set-back still is."""
    z = [0.15, 0.15, 0.2, 0.21, 0.21, 0.15, 0.15, 0.15, 0.15, 0.15, 0.15]  # came up 6 cm, set back at 0.5 s
    hands = [0.5, 0.3, 0.2, 0.21, 0.21, 0.15, 0.3, 0.5, 0.5, 0.5, 0.5]  # then the hands go away
    failed = {"g0": {"kind": "pick", "status": "failed", "end_s": 0.95, "released_s": 0.45}}
    r = judge(DRAWN, _arrays(z, hands, [3.0, 0.0]), failed, {"g0": "did not come up"}, 0.7, False, index=0)
    assert r["lifted"] and not r["dropped"] and not r["success"]
    # without the set-back's time the hands going away reads as a drop (what the bench said before)
    unmarked = {"g0": {k: v for k, v in failed["g0"].items() if k != "released_s"}}
    assert judge(DRAWN, _arrays(z, hands, [3.0, 0.0]), unmarked, {}, 0.7, False, index=0)["dropped"]
    # a box that slid out of the hands before the set-back is still a drop
    slid = [0.15, 0.15, 0.2, 0.21, 0.15, 0.15, 0.15, 0.15, 0.15, 0.15, 0.15]
    assert judge(DRAWN, _arrays(slid, [0.5, 0.3, 0.2, 0.21, 0.3, 0.3, 0.3, 0.5, 0.5, 0.5, 0.5], [3.0, 0.0]),
                 failed, {}, 0.7, False, index=0)["dropped"]


def test_refusals_are_counted_per_bucket_by_reason_numbers_aside():
    pick = ("pick: box 'box' (0.30x0.34x0.24 m, 4.7 kg, centre 0.12 m up): no stance can pick it up (32 tried, pelvis "
            "down to 0.47 m): waist_pitch_joint needs {} N m to hold still (its limit 35 N m); closest: heading -25 deg, "
            "pelvis 0.47 m")
    rows = [{"source": {"bucket": "floor"}, "target": {"bucket": "high"}, "refused": [pick.format(38), "place: holding no box"]},
            {"source": {"bucket": "floor"}, "target": {"bucket": "low"}, "refused": [pick.format(41)]},
            {"source": {"bucket": "table"}, "target": {"bucket": "floor"},
             "refused": ["place: from the stance the carry ended in, the hands get only within 3.4 cm of where the box "
                         "goes (planned: pelvis 0.50 m)"]},
            {"source": {"bucket": "low"}, "target": {"bucket": "low"}, "refused": []}]
    assert refusal_reason(pick.format(38)) == "pick: waist_pitch_joint needs # N m to hold still (its limit # N m)"
    assert refusal_table(rows) == {
        "from floor": {"pick: waist_pitch_joint needs # N m to hold still (its limit # N m)": 2},
        "to floor": {"place: from the stance the carry ended in, the hands get only within # cm of where the box goes": 1}}


def test_a_fall_is_reported_with_the_stage_it_happened_in():
    """The goal running when the robot fell, and what it was doing (its walk, or its whole-body plan's
    name: GoalContext.run and walk_to record it as the goal's "stage")."""
    arrays = _arrays([0.15, 0.3, 0.3, 0.2], [0.3, 0.3, 0.3, 0.2], [2.0, 1.0])
    info = {"g0": {"kind": "pick", "status": "reached", "end_s": 0.3, "stage": "pick"},
            "g1": {"kind": "place", "stage": "carry"}}
    r = judge(DRAWN, arrays, info, {}, 0.25, False, index=0)
    assert r["fell"] and r["fell_in"] == "place: carry"
    assert "fell (place: carry)" in _why(r)
    standing = judge(DRAWN, arrays, info, {}, 0.7, False, index=0)
    assert not standing["fell"] and standing["fell_in"] == "" and "fell" not in _why(standing)
