"""`g1 bench stall`: a stalled host with and without a command life on the link. The hold form is the
link's; one stall from the bench's range in real physics; the table and JSON from known trials."""

import json
from types import SimpleNamespace

import numpy as np

from g1_control.tools import bench_stall as B
from g1_control.types import MotorCommand


def test_the_hold_form_keeps_targets_and_gains_and_drops_torque_and_velocity_targets():
    command = MotorCommand(q_rad=np.full(29, 0.3), dq_radps=np.full(29, 2.0), kp=np.full(29, 40.0),
                           kd=np.full(29, 1.5), tau_nm=np.full(29, -4.0))
    command.enable[3] = False
    held = B.hold_form(command)
    assert np.all(held.q_rad == 0.3) and np.all(held.kp == 40.0) and np.all(held.kd == 1.5)
    assert not held.enable[3] and held.enable.sum() == 28
    assert not held.tau_nm.any() and not held.dq_radps.any()
    assert held.q_rad is not command.q_rad, "a copy: the tracker reuses its command's arrays"


def test_a_120_ms_stall_in_mid_stride_throws_the_robot_unless_the_command_expires():
    """One instant of the bench's range (29-DoF, 6.88 s into the walk, 1.88 s of 0.5 m/s forward walking):
    the last command resent for 120 ms threw the legs (a fall or an over-speed trip); expired into its
    hold form after 30 ms (3 ticks at 100 Hz), the robot walked on. (5.66 s until stop 41: since the
    estimator stopped integrating an accelerometer sample over a stall, the robot fed as_is there
    recovers, peak 25.8 rad/s.)"""
    as_is = B.run_trial("g1_29dof", 0.12, 6.88, "as_is")
    hold = B.run_trial("g1_29dof", 0.12, 6.88, "hold")
    assert as_is.fell, as_is
    assert not hold.fell and hold.min_pelvis_m > 0.6, hold
    assert hold.peak_dq_radps < as_is.peak_dq_radps


def _trial(variant, stall, at, mode, fell, peak):
    return B.StallTrial(variant, stall, at, mode, fell, "", peak, 0.7, 1.0)


def test_the_table_and_json_count_falls_per_variant_stall_and_mode(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(B, "STALLS_S", (0.04, 0.12))
    monkeypatch.setattr(B, "run_trial", lambda v, s, at, m: _trial(v, s, at, m, fell=s > 0.1 and m == "as_is",
                                                                     peak=30.0 if s > 0.1 and m == "as_is" else 9.0))
    out = tmp_path / "stall.json"
    assert B.main(SimpleNamespace(only="g1_23dof", trials=3, seed=5, json=str(out))) == 0
    text = capsys.readouterr().out
    assert "all stalls: as_is fell 3/6, hold fell 0/6" in text
    data = json.loads(out.read_text())
    assert data["instants_s"] == B.stall_instants(5, 3) and len(data["trials"]) == 12
    assert all(B.DRAW_FROM_S[0] <= t <= B.DRAW_FROM_S[1] for t in data["instants_s"])
    (short, long) = data["rows"]
    assert (short["stall_ms"], long["stall_ms"]) == (40, 120)
    assert long["as_is"] == {"trials": 3, "fell": 3, "peak_dq_median": 30.0, "peak_dq_max": 30.0}
    assert long["hold"]["fell"] == 0 and short["as_is"]["fell"] == 0
    assert data["life_ms"] == 30.0


def test_an_unknown_variant_is_refused_by_name():
    import pytest

    with pytest.raises(SystemExit, match="--only g1_12dof: no variant"):
        B.main(SimpleNamespace(only="g1_12dof", trials=1, seed=0, json=None))
