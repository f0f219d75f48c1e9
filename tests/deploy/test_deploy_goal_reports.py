"""Honest goal reports on the robot path (issue 24): `g1 sim-robot` and `g1 deploy
launch/sim2sim_goals.yaml --yes` as two processes. A robot reports no world pose: the reach relative
to the robot runs (the arm's encoders show the hand where the goal put it); the reach to a world point
is placed by the robot's own estimate (leg odometry, anchored where it started) and runs, judged by
the emulator's ground truth; a goal the control time cuts short is listed too. The console,
--json, summary.json and events.jsonl carry every goal's status and message. Also: --json is written
after an error past the preflight, and the dry run's verdict names a segment it did not reach (no NaN)."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from deploy_test_helpers import FAST, deploy_to_the_end, write_launch

from g1_control.cli.main import main
from g1_control.robot import g1
from tests.paths import LAUNCH_DIR

pytestmark = pytest.mark.timing



def _hand_offset_in_heading_frame(q_rad: np.ndarray, quat_wxyz: np.ndarray) -> np.ndarray:
    """The right hand point with the measured joints minus the same with the arms at default (the reach's
    'standing position'), in the heading frame: what the goal's offset_h_m asked for."""
    from g1_control.generator.goals.poses import PosePlanner

    poses = PosePlanner()
    q = np.concatenate([[0.0, 0.0, 0.0], quat_wxyz[[1, 2, 3, 0]], q_rad])
    standing = q.copy()
    arms = 7 + np.array(g1.ARM_JOINTS)
    standing[arms] = g1.DEFAULT_Q_RAD[np.array(g1.ARM_JOINTS)]
    d = poses.hand_point(q, 1) - poses.hand_point(standing, 1)
    w, x, y, z = quat_wxyz
    yaw = math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))
    c, s = math.cos(yaw), math.sin(yaw)
    return np.array([c * d[0] + s * d[1], -s * d[0] + c * d[1], d[2]])


def test_every_goal_is_reported_on_the_robot_path_and_the_relative_reach_runs(tmp_path, partition):
    report_path = tmp_path / "deploy.json"
    host, wire = deploy_to_the_end(partition, LAUNCH_DIR / "sim2sim_goals.yaml", report_path, tmp_path,
                                   emulator_flags=("--lower-gantry-on-policy",))
    console = "\n".join(host.seen)
    # said before anything moved: the preflight table's launch_file row
    assert ("; note: goal seg2.0 (reach left hand at (0.40, 0.20, 0.95)) is placed by the robot's own estimate (leg "
            "odometry, anchored where it starts: the scene's origin, facing +x)") in console
    assert console.index("is placed by the robot's own estimate") < console.index("zero torque: the robot is limp")
    assert "goals (the execution layer's own verdicts; a robot has no ground truth):" in console
    assert "  goal seg1.0 (reach right hand): reached" in console
    assert "  goal seg2.0 (reach left hand at (0.40, 0.20, 0.95)): reached" in console
    assert "localisation (leg odometry, anchored at the start): last pose (" in console
    assert "  goal seg3.0 (reach left hand): unfinished" in console

    report = json.loads(report_path.read_text())
    run_dir = report["run_dir"]
    summary = json.loads(Path(run_dir, "summary.json").read_text())
    events = [json.loads(line) for line in Path(run_dir, "events.jsonl").read_text().splitlines()]
    for goals in (report["goals"], summary["goals"], [e for e in events if e["type"] == "goal"]):
        assert [(g["goal_id"], g["status"]) for g in goals] == [("seg1.0", "reached"), ("seg2.0", "reached"),
                                                                ("seg3.0", "unfinished")]
    assert report["localisation"]["source"] == "leg odometry" and report["localisation"]["pose"] is not None
    notes = [e["text"] for e in events if e["type"] == "goal_note"]
    assert "hand over to the whole-body controller" in notes and "goal seg1.0: reached" in notes
    assert report["error"] == "" and not report["fault"]
    assert wire["first_damping_base_pos_w_m"][2] > 0.6, "standing when control ended"

    # The reach as the robot's own encoders saw it: held over 8-10.8 s of control (the world-point reach
    # of the left hand starts at 11 s and poses both arms anew)
    log = np.load(f"{run_dir}/log.npz")
    t = log["t_s"] - log["t_s"][0]
    first, control = report["transitions"][0]["t_s"], next(tr["t_s"] for tr in report["transitions"] if tr["to"] == "control")
    control_t0 = control - first
    held = (t > control_t0 + 8.0) & (t < control_t0 + 10.8)
    sp = log["q_rad"][held, g1.JOINT_INDEX["right_shoulder_pitch_joint"]]
    assert held.sum() > 100 and sp.max() < -0.3, "the right arm left its default (0.20 rad) and held the reach"
    offsets = np.array([_hand_offset_in_heading_frame(q, quat) for q, quat in
                        zip(log["q_rad"][held][::20], log["base_quat_wxyz"][held][::20])])
    err = np.linalg.norm(offsets - [0.25, 0.0, 0.20], axis=1)
    print(f"\nrobot-path reach (offset_h_m 0.25, 0, 0.20): hand offset from the measured joints "
          f"{offsets.mean(axis=0).round(3).tolist()}, error mean {err.mean() * 100:.1f} cm, max {err.max() * 100:.1f} cm")
    assert err.max() < 0.03


def test_json_is_written_after_an_error_past_the_preflight(tmp_path, partition, mock_robot, monkeypatch, capsys):
    import g1_control.deploy.session as session
    from g1_control.errors import G1ControlError

    def broken(*args, **kwargs):
        raise G1ControlError("the loop could not be built (test)")

    monkeypatch.setattr(session, "_control", broken)
    mock_robot().start()
    report_path = tmp_path / "report.json"
    code = main(["deploy", str(write_launch(tmp_path, FAST)), "--partition", partition, "--yes", "--json",
                 str(report_path)])
    assert code == 1 and "the loop could not be built (test)" in capsys.readouterr().err
    report = json.loads(report_path.read_text())
    assert report["error"] == "G1ControlError: the loop could not be built (test)"
    assert not report["refused"] and {r["status"] for r in report["preflight"]} <= {"pass", "skip"}


def test_the_dry_run_verdict_names_a_segment_it_did_not_reach(tmp_path):
    from g1_control.deploy.preflight import Preflight
    from g1_control.launch.schema import load_launch

    timeline = [{"duration_s": 11, "label": "stand"}, {"duration_s": 5, "vx_mps": 0.3, "label": "walk"}]
    launch = load_launch(write_launch(tmp_path, {"duration_s": 16, "input": {"timeline": timeline}}))
    pf = Preflight()
    assert pf.check_dry_run(launch)
    reason = pf.results["dry_run"].reason
    assert reason.endswith("; walk not reached (starts at 11.0 s, the dry run ran 10.0 s)"), reason
    assert "nan" not in reason
