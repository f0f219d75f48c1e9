"""Runs keep their data: `g1 launch` writes its run folder as it goes and closes it on SIGINT/SIGTERM
with the reason recorded; (`g1 deploy`: tests/deploy/test_deploy_run_folder.py)."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

from tests.paths import LAUNCH_DIR, REPO

pytestmark = pytest.mark.timing

ENV = {**os.environ, "PYTHONPATH": str(REPO) + os.pathsep + os.environ.get("PYTHONPATH", "")}


@pytest.mark.parametrize("sig", ["SIGINT", "SIGTERM"])
def test_a_signal_during_g1_launch_keeps_the_run_folder(tmp_path, sig):
    proc = subprocess.Popen([sys.executable, "-m", "g1_control.cli.main", "launch", str(LAUNCH_DIR / "sim_random.yaml"),
                             "--no-video", "--duration", "300", "--quiet", "--out", str(tmp_path)],
                            cwd=tmp_path, env=ENV, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        # Wait until the loop runs (its run folder's log grows as it goes), at most 30 s.
        deadline = time.monotonic() + 30
        while time.monotonic() < deadline and proc.poll() is None:
            time.sleep(0.5)
            if any(tmp_path.glob("sim_random-*/log/t_s.*")):
                break
        time.sleep(2.0)
        proc.send_signal(getattr(signal, sig))
        _out, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
    expected = 128 + getattr(signal, sig)
    assert proc.returncode == expected, (proc.returncode, err[-2000:])
    (run_dir,) = tmp_path.glob("sim_random-*")
    summary = json.loads((run_dir / "summary.json").read_text())
    assert summary["end_reason"] == f"{sig} received" and summary["status"] == "interrupted", summary
    log = np.load(run_dir / "log.npz")
    t = log["t_s"]
    assert len(t) > 50 and np.all(np.diff(t) > 0), "the per-tick log was kept up to the signal"
    assert abs(summary["duration_s"] - t[-1]) < 0.1
    assert list(log["joint_names"]) == list(json.loads((run_dir / "log" / "fields.json").read_text())["joint_names"])
