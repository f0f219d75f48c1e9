"""A step known only from perception, on the robot path (issue 24): `g1 sim-robot --scene
launch/sim2sim_step.yaml` (its world holds the 0.15 m platform and its perception topic reports it, with
2 cm / 3 deg noise, 0.1 s latency and 10 % dropouts) and `g1 deploy launch/sim2sim_step_seen.yaml` (whose
scene lists no platform) as two processes over DDS on lo. Judged by the emulator's ground truth: both soles
on the platform's top (height and footprint) at the end of the step up, both back on the floor and off its
footprint at the end of the step down. With
the perceived platforms ignored the step up refuses (the platform was never seen) and this goes red."""

from __future__ import annotations

import json

import numpy as np
import pytest
from deploy_test_helpers import deploy_to_the_end

from g1_control.tools.judge_sim2sim import judge
from tests.paths import LAUNCH_DIR

pytestmark = pytest.mark.timing

NOISE = ("--perception-noise-m", "0.02", "--perception-noise-deg", "3", "--perception-latency-s", "0.1",
         "--perception-dropout", "0.1")


def test_a_step_known_only_from_perception_is_stepped_onto_and_off_over_dds(tmp_path, partition):
    world, launch = LAUNCH_DIR / "sim2sim_step.yaml", LAUNCH_DIR / "sim2sim_step_seen.yaml"
    truth_path, report_path = tmp_path / "truth.npz", tmp_path / "deploy.json"
    _, wire = deploy_to_the_end(partition, launch, report_path, tmp_path,
                                emulator_flags=("--lower-gantry-on-policy", "--scene", str(world),
                                                "--record", str(truth_path), *NOISE))
    report = json.loads(report_path.read_text())
    assert report["error"] == "" and not report["fault"], report["end_reason"]  # no deadline trip, no fall
    seen = report["localisation"]["perception"]
    real = wire["platforms_w_m"]["step"]
    where = seen["platforms_w_m"]["step"]
    with np.load(truth_path) as npz:
        truth = {k: npz[k] for k in npz.files}
    up, down = judge(report, truth)
    print(f"\nperception: {seen['platform_frames']} platform frames, {wire['perception']['dropped']} of "
          f"{wire['perception']['measured']} dropped; the step seen at {np.round(where['center_xy_m'], 3).tolist()} "
          f"(truth {real['center_xy_m']}, in the estimate's frame); both feet on top {up['both_feet_on_top_s']:.1f} s, "
          f"on top at the end of the step up: {up['on_top_at_end']}; on the floor at the end: {down['on_floor_at_end']}")
    assert (up["status"], down["status"]) == ("reached", "reached"), (up.get("message"), down.get("message"))
    record = report["goals"][0]["record"]
    assert record["platform"] == "step" and record["platform_from"] == "perception"
    assert up["on_top_at_end"] and up["both_feet_on_top_s"] > 1.0 and down["on_floor_at_end"]
    # where the soles stood (ground truth) when each goal ended: over the platform's top, then off it
    half = np.array(real["size_xy_m"]) / 2
    for goal, over in ((report["goals"][0], True), (report["goals"][1], False)):
        row = int(np.searchsorted(truth["t_s"], goal["record"]["end_s"])) - 1
        inside = np.all(np.abs(truth["soles_w_m"][row][:, :2] - real["center_xy_m"]) < half, axis=1)
        assert inside.all() if over else not inside.any(), (goal["goal_id"], truth["soles_w_m"][row])
