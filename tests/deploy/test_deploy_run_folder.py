"""`g1 deploy` writes a run folder as it goes (per-tick log, state-machine transitions, safety
events, summary with the end reason), and a normal end is not logged as an error."""

from __future__ import annotations

import json
import logging

import numpy as np
import pytest
from deploy_test_helpers import write_launch

from g1_control.deploy.session import DeployOptions, deploy

pytestmark = pytest.mark.timing


def test_deploy_writes_a_run_folder_and_a_normal_end_is_not_an_error(tmp_path, partition, mock_robot, caplog):
    mock_robot().start()
    launch = write_launch(tmp_path, {"deploy": {"state_window_s": 0.3, "input_check_s": 0.1},
                                     "output": {"dir": str(tmp_path / "runs")}})
    caplog.set_level(logging.INFO)
    report = deploy(launch, DeployOptions(yes=True, partition=partition, duration_s=2.0), say=lambda line: None)
    assert not report.fault and report.end_reason.startswith("control time over")
    errors = [r for r in caplog.records if r.levelno >= logging.ERROR]
    assert not errors, [r.getMessage() for r in errors]

    (run_dir,) = (tmp_path / "runs").glob("sim2sim-*")
    summary = json.loads((run_dir / "summary.json").read_text())
    assert summary["status"] == "completed" and summary["end_reason"].startswith("control time over")
    log = np.load(run_dir / "log.npz")
    assert len(log["t_s"]) > 100 and log["q_rad"].shape[1] == 29
    events = [json.loads(line) for line in (run_dir / "events.jsonl").read_text().splitlines()]
    transitions = [e for e in events if e["type"] == "transition"]
    assert [e["to"] for e in transitions] == ["ramp", "hold", "control", "damping"]
    assert any(e["type"] == "safety" for e in events)
