"""`g1 bench objects --carry` in physics: one drawn scene (a 3.4 kg box from a 0.82 m table to a 0.67 m
one, 4.7 m away) run on the whole-body controller and judged from MuJoCo's ground truth: the box is
lifted, carried in the controller's own gait (handling.walk_in_gait), set down within 3 cm, upright,
never dropped, and the robot does not fall. The scene is one placed with both the suite's OpenBLAS
kernel (tests/conftest.py) and an AVX-512 host's own (1.4 cm each); seed 200 trial 0, a 3.9 kg box, was
placed with the latter and not picked up with the former (the lift 6 cm behind the plan)."""

from __future__ import annotations

from g1_control.tools.bench_objects import run_trial


def test_a_drawn_carry_walks_the_box_4_7_m_in_the_gait_and_sets_it_down():
    r = run_trial(205, 1, carry=True)
    assert r["mass_kg"] > 3.0 and r["carry_m"] > 4.5  # the scene this test is about
    assert r["walked"] == "gait", r
    assert r["success"] and not r["fell"] and not r["dropped"], r
    assert r["place_error_xy_m"] < 0.03 and r["tilt_deg"] < 3.0
