"""`g1 bench objects --tracker wbc`: the objects scenes on the whole-body controller alone (250 Hz), which
walks a held box in its own gait. Scene 141.16, a 4.4 kg box from a 0.86 m table to a 0.88 m one: carried
in whole-body steps the robot fell (the tracking layer before it handed such walks to its WBC's gait);
on the WBC the box is lifted, carried in the gait and set down within 3 cm, upright, never dropped, no
fall (MuJoCo's ground truth; 1.0 cm with both the suite's OpenBLAS kernel and an AVX-512 host's own)."""

from __future__ import annotations

import argparse

import pytest

from g1_control.tools import bench_objects
from g1_control.tools.bench_objects import run_trial


def test_a_heavy_box_between_two_high_tables_is_carried_in_the_wbc_gait_and_placed():
    r = run_trial(141, 16, tracker="wbc")
    assert r["mass_kg"] > 4.0 and r["source"]["bucket"] == r["target"]["bucket"] == "high"  # the scene
    assert r["tracker"] == "wbc" and r["walked"] == "gait", r
    assert r["success"] and not r["fell"] and not r["dropped"], r
    assert r["place_error_xy_m"] < 0.03 and r["tilt_deg"] < 3.0


def test_an_unknown_tracker_is_refused_before_anything_runs():
    with pytest.raises(ValueError, match="tracker 'policy': one of layer, wbc"):
        run_trial(141, 16, tracker="policy")


def test_the_cli_passes_its_tracker_to_every_trial_and_keeps_carry_on_the_wbc(monkeypatch, tmp_path):
    seen = []

    def fake_fan_out(fn, tasks, jobs, ray):
        seen.extend(tasks)
        return []

    monkeypatch.setattr("g1_control.fanout.fan_out", fake_fan_out)
    args = argparse.Namespace(trials=3, seed=7, jobs=1, ray=None, json=str(tmp_path / "o.json"), carry=False,
                              tracker="wbc")
    assert bench_objects.main(args) == 0
    assert seen == [(7, i, False, True, "wbc") for i in range(3)]
    seen.clear()
    args.tracker = None
    bench_objects.main(args)
    assert seen == [(7, i, False, True, "layer") for i in range(3)]
    args.carry, args.tracker = True, "layer"
    with pytest.raises(ValueError, match="--carry runs on the whole-body controller"):
        bench_objects.main(args)


def test_a_box_held_up_high_is_walked_with_the_pelvis_at_its_walking_height():
    """Scene 165.5: a 1.3 kg box from a 0.93 m table, raised to ~1.1 m to clear the 0.57 m target's top.
    The arms and the box held up lift the CoM above the pelvis; with the CoM held at the default pose's
    walking height (WbcConfig.walking_held_pelvis off) the pelvis sank 0.77 -> 0.59 m, the robot drifted
    turning on the spot and fell. With the pelvis held at its walking height it is carried and placed."""
    r = run_trial(165, 5, tracker="wbc")
    assert r["source"]["height_m"] > 0.9 and r["mass_kg"] < 2.0  # the scene
    assert r["walked"] == "gait", r
    assert r["success"] and not r["fell"] and not r["dropped"], r
    assert r["place_error_xy_m"] < 0.05
