"""`g1 bench objects` in physics, a pick from a stance off the box's line (stances.SIDE_STEPS_M): scene
134.16, a 2.0 kg 0.41 x 0.21 x 0.16 m box on a 0.95 m table, turned 21 deg to its edge, to go on a 0.57 m
table. Every stance on the box's line is refused before anything moves (the closest: an upper arm in
the table's top); from 6 cm to its left, standing, the box is lifted, carried and set
down within 3 cm, upright, never dropped, no fall (MuJoCo's ground truth; placed with both the suite's
OpenBLAS kernel and an AVX-512 host's own: 0.2 cm each)."""

from __future__ import annotations

from g1_control.tools.bench_objects import run_trial


def test_an_aslant_box_is_picked_from_beside_its_line_and_placed():
    r = run_trial(134, 16)
    assert 0.95 > r["source"]["height_m"] > 0.9 and r["mass_kg"] < 2.1  # the scene this test is about
    assert "m to its left" in (r["pick_stance"] or ""), r["pick_stance"]
    assert r["success"] and not r["fell"] and not r["dropped"], r
    assert r["place_error_xy_m"] < 0.03 and r["tilt_deg"] < 3.0


def test_the_far_hand_reaches_across_without_meeting_the_table():
    """133.1: a 2.3 kg box on a 0.88 m table, picked from 6 cm to its right. With the hand points of the
    via pose beside the box and the plain blend from there to the pre-grasp pose, the far hand met the
    table's top and the robot fell at the pick (both OpenBLAS kernels); with the via pose in front of the
    body and the hands straight from it (either alone suffices here), the box is lifted and held, no fall.
    Its place (a 0.18 m table) is refused: no squat holds it that low (the waist's 35 N m)."""
    r = run_trial(133, 1)
    assert "m to its right" in (r["pick_stance"] or ""), r["pick_stance"]
    assert r["lifted"] and r["held"] and not r["fell"] and not r["dropped"], r
    assert r["place_status"] == "failed" and "waist_pitch_joint" in r["refused"][0]
