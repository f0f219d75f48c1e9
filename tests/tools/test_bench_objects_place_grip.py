"""A place sets the box down where the pick took it in the hands (context.Held.hand_dz_m), not where a pick at
the place would take it (stances.hand_height: a box whose centre is below LOW_BOX_Z_M is gripped higher).
Before, a tall box taken at its centre from a table and set on a low support or the floor was planned as
gripped high, so it was let go 9-11 cm above its rest and fell over, while the place reported "reached".
Judged from MuJoCo's ground truth by `g1 bench objects`' judge (lifted, held, placed within 10 cm,
upright, never dropped, no fall).

Scene 165.12: a 0.39 m tall 2.2 kg box from a 0.52 m table to a 0.23 m one (was toppled, tilt 90 deg).
Scene 163.7: a 0.45 m tall 0.9 kg box from a 0.67 m table to the floor: with its centre grip no stance
reaches the floor, so the place is refused before moving and the box stays held (was toppled)."""

from __future__ import annotations

from g1_control.generator.goals.stances import LOW_BOX_Z_M
from g1_control.tools.bench_objects import run_trial


def test_a_tall_box_taken_at_its_centre_is_set_down_upright_on_a_low_table():
    r = run_trial(165, 12)
    assert r["target"]["bucket"] == "low" and r["size_m"][2] > 0.35  # the scene: a tall box, a low target
    assert r["success"] and r["upright"] and not r["dropped"] and not r["fell"], r
    assert r["tilt_deg"] < 5.0


def test_a_floor_place_that_would_let_it_go_in_the_air_is_refused_and_the_box_stays_held():
    r = run_trial(163, 7)
    assert r["target"]["bucket"] == "floor" and r["source"]["height_m"] + r["size_m"][2] / 2 > LOW_BOX_Z_M
    assert r["lifted"] and r["held"] and r["pick_status"] == "reached", r
    assert r["place_status"] == "failed", r
    assert any("no stance can set it down there" in m for m in r["refused"]), r["refused"]
    assert not r["dropped"] and not r["fell"] and r["tilt_deg"] < 10.0, r
