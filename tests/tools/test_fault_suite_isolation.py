"""One fault trial whose setup fails (e.g. a stall on a loaded host trips the fresh safety layer before
the fault is injected) is retried with a fresh robot, and if it keeps failing it is recorded as a
failed trial: the other trials still run (no cascade). Fakes stand in for DDS here; the real suite
is tests/tools/test_fault_injection.py."""

from __future__ import annotations

import math

from g1_control.tools import fault_suite
from g1_control.tools.fault_suite import FaultResult


class _FakeEmulator:
    alive = True

    def __init__(self, partition: str):
        self.partition = partition

    def ask(self, word: str) -> dict:
        return {"fault": word, "t_s": 0.0}

    def close(self) -> None:
        pass


class _FakeRobot:
    def close(self) -> None:
        pass


def _patch(monkeypatch, failures: dict[str, int]):
    calls: dict[str, int] = {}

    def trial(fault, emulator, robot):
        calls[fault] = calls.get(fault, 0) + 1
        if calls[fault] <= failures.get(fault, 0):
            raise RuntimeError(f"safety tripped before fault '{fault}' was injected: stale_state: newest state is "
                               "53.5 ms old (limit 50 ms)")
        return FaultResult(fault, "tilt" if fault == "tilt" else "joint_overspeed", 10.0, 5.0, 15.0, "ok")

    monkeypatch.setattr(fault_suite, "_Emulator", _FakeEmulator)
    monkeypatch.setattr(fault_suite, "_open_robot", lambda partition: _FakeRobot())
    monkeypatch.setattr(fault_suite, "run_in_process_fault", trial)
    return calls


def test_a_setup_stall_is_retried_with_a_fresh_robot(monkeypatch):
    calls = _patch(monkeypatch, {"tilt": 1})
    results = {r.fault: r for r in fault_suite.run_suite(("tilt", "overspeed"), progress=False)}
    assert calls["tilt"] == 2
    assert results["tilt"].tripped_as == "tilt" and math.isfinite(results["tilt"].total_ms)


def test_a_trial_whose_setup_keeps_failing_does_not_cascade(monkeypatch):
    _patch(monkeypatch, {"tilt": 99})
    results = {r.fault: r for r in fault_suite.run_suite(("tilt", "overspeed"), progress=False)}
    assert results["tilt"].tripped_as == "(setup failed)" and not math.isfinite(results["tilt"].total_ms)
    assert "53.5 ms old" in results["tilt"].detail
    assert results["overspeed"].tripped_as == "joint_overspeed"
