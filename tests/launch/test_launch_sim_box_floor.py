"""launch/sim_box_floor.yaml as a user runs it (issue 25's "a box picked from the floor and put on a
0.75 m table"): the outcomes from the GoalWatcher's ground truth, the box's own pose in MuJoCo."""

import numpy as np

from g1_control.launch.builder import build_loop
from g1_control.launch.schema import load_launch
from g1_control.report.outcomes import GoalWatcher
from tests.paths import LAUNCH_DIR


def test_sim_box_floor_picks_the_box_from_the_floor_and_puts_it_on_the_table_by_ground_truth():
    launch = load_launch(LAUNCH_DIR / "sim_box_floor.yaml")
    box_cfg = launch.scene.boxes[0]
    table = launch.scene.block("table")
    assert box_cfg.stands_on == "floor" and table is not None and abs(table.height_m - 0.75) < 1e-9
    loop = build_loop(launch)
    loop.reset()
    watcher = GoalWatcher(loop)
    loop.scheduler.run(round(launch.total_duration_s * loop.rates.lowlevel_hz), progress=watcher.tick)
    assert not loop.fell
    pick, place = watcher.outcomes()
    assert pick["status"] == place["status"] == "reached", (pick, place)
    notes = [text for _, text in loop.generator.log]
    assert any(text.startswith("pick stance:") and "deep squat" in text for text in notes), notes
    # where physics put the box: lifted off the floor, then resting on the table's top, upright
    box = watcher.arrays()["box_box"]
    half_z = box_cfg.size_m[2] / 2
    assert abs(box[0, 2] - half_z) < 0.01, "it started on the floor"
    assert pick["box_rise_m"] > 0.25
    assert table.contains_xy(box[-1, :2]), "it ended on the table"
    assert abs(box[-1, 2] - (table.height_m + half_z)) < 0.01
    assert place["place_error_xy_m"] < 0.04 and place["box_tilt_deg"] < 3.0, place
    assert float(np.hypot(*(box[-1, :2] - box[0, :2]))) > 1.5, "carried, not nudged"
