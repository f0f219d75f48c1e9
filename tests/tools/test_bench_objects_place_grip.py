"""A place sets the box down from where the pick took it in the hands (context.Held.hand_dz_m), and a pick
takes a box where the place queued after it will want it (handling.place_grip_m). Before, the place planned
its hands by stances.hand_height at the place (a box whose centre rests below LOW_BOX_Z_M is gripped higher
than at its centre): a tall box taken at its centre from a table and set on a low support or the floor was
let go 9-11 cm above its rest and fell over, while the place reported "reached". Judged from MuJoCo's ground
truth by `g1 bench objects`' judge (lifted, held, placed within 10 cm, upright, never dropped, no fall).

Scene 165.12: a 0.39 m tall 2.2 kg box from a 0.52 m table to a 0.23 m one (toppled before, tilt 90 deg).
Scene 163.7: a 0.45 m tall 0.9 kg box from a 0.67 m table to the floor (toppled before; with only the place
fixed, its centre grip reached no floor stance and the place was refused)."""

from __future__ import annotations

from g1_control.generator.goals.stances import LOW_BOX_Z_M
from g1_control.tools.bench_objects import run_trial


def test_a_tall_box_taken_at_its_centre_is_set_down_upright_on_a_low_table():
    r = run_trial(165, 12)
    assert r["target"]["bucket"] == "low" and r["size_m"][2] > 0.35  # the scene: a tall box, a low target
    assert r["success"] and r["upright"] and not r["dropped"] and not r["fell"], r
    assert r["tilt_deg"] < 5.0


def test_a_tall_box_going_to_the_floor_is_taken_high_and_set_down_upright():
    r = run_trial(163, 7)
    # the scene: a tall box resting above LOW_BOX_Z_M (a pick there alone grips its centre), for the floor
    assert r["target"]["bucket"] == "floor" and r["source"]["height_m"] + r["size_m"][2] / 2 > LOW_BOX_Z_M
    assert r["size_m"][2] > 0.4
    assert r["success"] and r["upright"] and not r["dropped"] and not r["fell"], r
    assert r["place_error_xy_m"] < 0.05 and r["tilt_deg"] < 5.0
