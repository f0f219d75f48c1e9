"""`g1 bench wbc`: a short run of the walk prints its table and writes the JSON; its touchdowns are
solved as asked (no relaxed tick), its warm starts reset on contact changes."""

import json
from types import SimpleNamespace

from g1_control.tools import bench_wbc


def test_a_short_run_walks_and_reports_its_solver_counts(tmp_path, capsys):
    out = tmp_path / "wbc.json"
    assert bench_wbc.main(SimpleNamespace(seconds=4.0, json=str(out))) == 0
    text = capsys.readouterr().out
    assert "no fall" in text and "whole act()" in text and "warm starts reset for a contact change" in text
    report = json.loads(out.read_text())
    assert not report["fell"] and report["ticks"] == 1000
    assert 0.2 < report["velocity_true_h"][0] < 0.4, report["velocity_true_h"]
    assert report["ticks_relaxed"] == 0 and report["ticks_unsolved"] == 0
    assert report["qp_contact_resets"] > 0 and report["qp_cold_retries"] == 0
    assert report["act_p99_us"] >= report["act_p50_us"] > 0
    # the replay: the same problems, in order, solved as shipped and with the warm starts' parameters carried
    # over; carried over, the touchdowns' warm starts exit unsolved (as every touchdown's did until stop 42)
    shipped, carried = report["replay"]["shipped"], report["replay"]["carried_over"]
    assert shipped["problems"] == carried["problems"] == 1000
    assert shipped["cold_retries"] == 0 and carried["cold_retries"] >= 4
    assert "warm starts, the walk's first 1000 problems solved again" in text
