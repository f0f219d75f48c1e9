"""`g1 bench wbc`: a short run of the walk prints its table and writes the JSON, with the warm-start
replay: carried over (the default), the touchdowns' warm starts exit unsolved; reset on contact changes
(QpConfig.contact_change_mu_in), none does."""

import json
from types import SimpleNamespace

from g1_control.tools import bench_wbc


def test_a_short_run_walks_and_reports_its_solver_counts(tmp_path, capsys):
    out = tmp_path / "wbc.json"
    assert bench_wbc.main(SimpleNamespace(seconds=4.0, json=str(out))) == 0
    text = capsys.readouterr().out
    assert "no fall" in text and "whole act()" in text and "warm starts unsolved" in text
    report = json.loads(out.read_text())
    assert not report["fell"] and report["ticks"] == 1000
    assert 0.2 < report["velocity_true_h"][0] < 0.4, report["velocity_true_h"]
    # the default carries the proximal parameters over: each false exit is re-solved relaxed by the tracker
    assert report["ticks_relaxed"] == report["qp_warm_exits"] >= 4 and report["ticks_unsolved"] == 0
    assert report["qp_contact_resets"] == report["qp_cold_retries"] == 0
    assert report["act_p99_us"] >= report["act_p50_us"] > 0
    # the replay: the same problems, in order, with the parameters carried over and reset on contact changes
    carried, reset = report["replay"]["carried_over"], report["replay"]["reset"]
    assert carried["problems"] == reset["problems"] == 1000
    assert carried["warm_exits"] >= 4 and 4 * reset["warm_exits"] <= carried["warm_exits"], (carried, reset)
    assert "warm starts, the walk's first 1000 problems solved again" in text
