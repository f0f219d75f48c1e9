"""`g1 bench bottle`: its drawn scenes (pure, within their ranges, the target on the table) and one
trial through `main`, judged from ground truth (the printed line and the JSON)."""

from __future__ import annotations

import json
from types import SimpleNamespace

import numpy as np

from g1_control.tools import bench_bottle as bb


def test_scenes_are_drawn_from_their_ranges_the_same_for_the_same_seed_and_index():
    scenes = [bb.draw_scene(7, i) for i in range(40)]
    assert scenes[3] == bb.draw_scene(7, 3) and scenes[3] != bb.draw_scene(8, 3)
    assert {s["hand"] for s in scenes} == {"left", "right"}
    for s in scenes:
        b = s["bottle"]
        side = 1.0 if s["hand"] == "left" else -1.0
        assert bb.TABLE_HEIGHT_M[0] <= s["table_height_m"] <= bb.TABLE_HEIGHT_M[1]
        assert bb.RADIUS_M[0] <= b["radius_m"] <= bb.RADIUS_M[1] and bb.MASS_KG[0] <= b["mass_kg"] <= bb.MASS_KG[1]
        assert bb.TABLE_DISTANCE_M[0] <= np.hypot(*s["table"]["center_xy_m"]) <= bb.TABLE_DISTANCE_M[1]
        launch = bb.scene_launch(s)  # the launch file's own validation accepts every draw
        table, bottle = launch.scene.tables[0], launch.scene.bottles[0]
        assert bottle.radius_m == b["radius_m"] and launch.backend.hands == "dex3"
        # in the table's frame: near the side facing the robot (-x), put down across (y) towards the other hand
        local, target = table.local_xy(np.array(b["xy_m"])), table.local_xy(np.array(s["target_xy_m"]))
        inset = local[0] - b["radius_m"] + table.half[0]
        assert bb.INSET_M[0] - 1e-9 <= inset <= bb.INSET_M[1] + 1e-9 and abs(local[1]) <= bb.ALONG_M
        assert bb.MOVE_M[0] <= -side * (target[1] - local[1]) <= bb.MOVE_M[1] and abs(target[0] - local[0]) <= 0.03
        assert table.contains_xy(np.array(s["target_xy_m"]), margin_m=b["radius_m"]), "put down wholly on the top"
    assert np.ptp([s["table_height_m"] for s in scenes]) > 0.1


def test_main_runs_a_trial_prints_it_and_writes_the_json(tmp_path, capsys):
    out = tmp_path / "bottle.json"
    code = bb.main(SimpleNamespace(seed=1, trials=1, json=str(out), jobs=1, ray=None))
    text = capsys.readouterr().out
    data = json.loads(out.read_text())
    row = data["trials"][0]
    assert code == 0 and data["falls"] == 0
    assert row["hand"] == "left" and row["placed"] and row["peak_squeeze_nm"] <= row["torque_limit_nm"]
    assert "bottle: placed 1/1" in text and "falls 0" in text


def test_a_bottle_is_picked_with_one_dex3_hand_and_put_down_upright_within_the_squeeze_limit():
    """g1 bench bottle's trial 8 of seed 2 (the right hand), in full, but put down 0.40 m outward (the draw:
    0.08-0.18 m the other way): the walk to the bottle, the whole-body controller, the grasp through the
    hands' safety layer, the bottle's weight and its moment about the hand point in the controller's
    dynamics (without the moment the palm tilted 25 deg and the bottle toppled at the release; without
    the grasp's give-way a thumb squeezed 0.73 N m against the 0.5 N m limit), and a sidestep to the
    place, out of the hand's reach from the pick's stance."""
    scene = bb.draw_scene(2, 8)
    table = scene["table"]
    c, s = np.cos(table["yaw_rad"]), np.sin(table["yaw_rad"])
    x, y = scene["bottle"]["xy_m"]
    scene["target_xy_m"] = (x + 0.40 * s, y - 0.40 * c)  # 0.40 m along the table's -y: outward, past the right hand
    r = bb.run_scene(scene)
    assert not r["fell"] and not r["refused"], r
    assert any("walking to the stance" in line for line in r["log"])
    assert any("stepping to put it down" in line for line in r["log"])
    assert r["lifted"] and r["held"] and r["rise_m"] > 0.08
    assert r["placed"] and r["place_error_m"] < 0.04 and r["tilt_deg"] < 3.0
    assert 0.3 < r["peak_squeeze_nm"] <= r["torque_limit_nm"]


def test_carry_scenes_put_the_bottle_on_a_second_table_away_from_the_first_with_a_clear_walk():
    scenes = [bb.draw_scene(5, i, True) for i in range(40)]
    assert scenes[2] == bb.draw_scene(5, 2, True) and scenes[2]["bottle"] == bb.draw_scene(5, 2)["bottle"]
    assert {s["hand"] for s in scenes} == {"left", "right"}
    for s in scenes:
        a, b = np.array(s["table"]["center_xy_m"]), np.array(s["table_b"]["center_xy_m"])
        assert bb.CARRY_DISTANCE_M[0] <= np.hypot(*b) <= bb.CARRY_DISTANCE_M[1] and np.hypot(*(b - a)) >= 1.2
        assert bb.TABLE_HEIGHT_M[0] <= s["target_height_m"] <= bb.TABLE_HEIGHT_M[1]
        launch = bb.scene_launch(s)  # two tables, validated by the launch file's own rules
        tables = {t.name: t for t in launch.scene.tables}
        assert set(tables) == {"table", "table_b"}
        assert tables["table_b"].height_m == s["target_height_m"]
        target = np.array(s["target_xy_m"])
        r = s["bottle"]["radius_m"]
        assert tables["table_b"].contains_xy(target, margin_m=r) and not tables["table"].contains_xy(target)
        local = tables["table_b"].local_xy(target)
        assert bb.INSET_M[0] - 1e-9 <= local[0] - r + tables["table_b"].half[0] <= bb.INSET_M[1] + 1e-9
        place = launch.input.timeline[2].goals[0]
        assert place.target == "table_b" and place.pos_w_m[2] == s["target_height_m"]
    assert np.ptp([s["target_height_m"] - s["table_height_m"] for s in scenes]) > 0.1  # higher and lower tops


def test_a_bottle_is_carried_to_a_second_table_and_put_down_upright():
    """g1 bench bottle --carry, seed 10 trial 1: a 0.80 m table to a 0.84 m one 1.4 m away, turned 75 deg:
    the bottle brought close to the body, the walk (back off, turn, walk) in the whole-body controller's own
    gait with the arm held, the steps into the stance, and the place from there. (Carried at arm's length
    and 4 cm lower than the pick's stand, as first built, its base met the second table's edge and the
    robot fell.)"""
    r = bb.run_scene(bb.draw_scene(10, 1, True))
    assert not r["fell"] and not r["refused"], r
    assert any("carrying it to the stance beside the point (held close" in line for line in r["log"]), r["log"]
    assert any("stand holding 'bottle'" in line for line in r["log"]), "walked in the gait, not in whole-body steps"
    assert r["lifted"] and r["held"] and r["slip_m"] < bb.DROP_M  # 2.2 cm in the gait (1.6 in whole-body steps)
    assert r["placed"] and r["place_error_m"] < 0.04 and r["tilt_deg"] < 3.0
    assert 0.3 < r["peak_squeeze_nm"] <= r["torque_limit_nm"]


def test_without_a_gait_the_bottle_is_carried_in_whole_body_steps():
    """The same scene with a tracker that has no gait of its own (GoalConfig.walk_while_holding off): back off,
    turn and walk in whole-body steps with the arm held, then the place."""
    r = bb.run_scene(bb.draw_scene(10, 1, True), gait=False)
    assert not r["fell"] and not r["refused"], r
    assert not any("stand holding" in line for line in r["log"]), "no gait walk"
    assert r["lifted"] and r["held"] and r["placed"] and r["place_error_m"] < 0.04 and r["tilt_deg"] < 3.0
