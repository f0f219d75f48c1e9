"""The hands' way to a box on the tracking layer, `g1 bench objects` trials judged from ground truth.

148.6: a 0.8 kg box on a 0.93 m table, picked from a stance on its line. Along the joint-space blend
from the via pose to the pre-grasp pose the left hand rose into the top's underside and the robot fell
at the pick (main, traced); with the hands going straight where the blend meets the top
(stances.straight_poses, given the support) it is lifted and placed."""

from g1_control.generator.goals import handling
from g1_control.tools.bench_objects import run_trial


def test_148_6_goes_straight_where_the_blend_meets_the_top_and_is_placed(monkeypatch):
    calls = []
    real = handling.straight_poses

    def spy(*args):
        out = real(*args)
        calls.append((len(args), len(out)))
        return out

    monkeypatch.setattr(handling, "straight_poses", spy)
    r = run_trial(148, 6)
    assert not r["fell"] and r["pelvis_min_m"] > 0.5
    assert r["lifted"] and r["held"] and not r["dropped"]
    assert r["placed"] and r["upright"] and r["success"], r
    assert "0.00 m to its" not in r["pick_stance"] and " to its " not in r["pick_stance"]  # on the line
    assert any(n == 9 and made > 0 for n, made in calls), calls  # given the support, and it made poses


def test_145_1_the_wrists_go_around_the_tops_edge_and_the_box_is_lifted():
    """145.1: a 5.1 kg box on a 0.89 m table. On main the left wrist rose into the top's underside on
    the way to the via pose (the hand points and elbows kept clear) and the robot fell at the pick;
    with the wrists kept WRIST_CLEAR_M from the top the hands go around it and the box is lifted and
    held. Its place, on the floor, is refused before anything moves (0.16 m tall: the hands would hold it
    9 cm above the ground)."""
    r = run_trial(145, 1)
    assert not r["fell"] and r["pelvis_min_m"] > 0.5
    assert r["lifted"] and r["held"] and not r["dropped"], r
    assert r["refused"] and r["refused"][-1].startswith("place: "), r["refused"]
