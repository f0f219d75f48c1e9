"""launch/sim_bottle.yaml as a user runs it: the goals' outcomes from the GoalWatcher's ground truth
(the bottle's own pose, against the hand that holds it), with the G1's Dex3 fingers driven by the loop."""

import numpy as np

from g1_control.launch.builder import build_loop
from g1_control.launch.schema import load_launch
from g1_control.report.outcomes import GoalWatcher, outcome_line
from tests.paths import LAUNCH_DIR


def _run(name: str):
    """The launch file run as `g1 launch` runs it, its goals watched from ground truth."""
    launch = load_launch(LAUNCH_DIR / name)
    loop = build_loop(launch)
    assert loop.hands is not None and loop.chain["hands"].startswith("Dex3-1")
    loop.reset()
    watcher = GoalWatcher(loop)
    loop.scheduler.run(round(launch.total_duration_s * loop.rates.lowlevel_hz), progress=watcher.tick)
    assert not loop.fell
    return launch, loop, watcher


def test_sim_bottle_picks_the_bottle_and_puts_it_down_upright_by_ground_truth():
    launch, loop, watcher = _run("sim_bottle.yaml")
    pick, place = watcher.outcomes()
    assert pick["status"] == place["status"] == "reached", (pick, place)
    assert pick["object_kind"] == "bottle" and 0.08 < pick["box_rise_m"] < 0.11 and pick["slip_m"] < 0.01
    assert place["place_error_xy_m"] < 0.04 and place["box_tilt_deg"] < 3.0 and abs(place["place_error_z_m"]) < 0.01
    assert "bottle lifted" in outcome_line(pick)
    bottle = watcher.arrays()["bottle_bottle"]
    start = launch.scene.bottle_center(launch.scene.bottles[0])
    assert np.allclose(bottle[0, :3], start, atol=0.003), "recorded where it stood"
    assert not loop.hands.tripped


def test_sim_bottle_carry_walks_the_bottle_to_the_second_table_and_puts_it_down_upright():
    launch, loop, watcher = _run("sim_bottle_carry.yaml")
    pick, place = watcher.outcomes()
    assert pick["status"] == place["status"] == "reached", (pick, place)
    assert any("carrying it to the stance beside the point" in text for _, text in loop.generator.log)
    assert place["place_error_xy_m"] < 0.04 and place["box_tilt_deg"] < 3.0 and abs(place["place_error_z_m"]) < 0.01
    bottle = watcher.arrays()["bottle_bottle"]
    table_b = launch.scene.block("side_table")
    assert table_b.contains_xy(bottle[-1, :2]), "it ended on the second table"
    assert float(np.hypot(*(bottle[-1, :2] - bottle[0, :2]))) > 1.2, "carried, not nudged"
    assert not loop.hands.tripped
