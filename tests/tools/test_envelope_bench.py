"""g1 bench envelope at small scale: a direction's limit is the last command of its ladder that the
tracker delivers (ground truth), and a ladder whose first command misses is walked down."""

from g1_control.tools import bench_envelope


def test_direction_limit_stops_at_the_first_command_not_delivered():
    log = []
    # The default style walks 0.5 m/s forward; 1.0 m/s is beyond the policy (it reaches ~0.57).
    assert bench_envelope.direction_limit("default", 0, (0.5, 1.0), log) == 0.5
    assert [p["met"] for p in log] == [True, False]
    assert log[1]["error_pct"] > 15.0


def test_a_first_command_that_misses_is_walked_down(monkeypatch):
    monkeypatch.setattr(bench_envelope, "BELOW", {1: (0.2,)})
    assert bench_envelope.direction_limit("default", 1, (0.45,), []) == 0.2
