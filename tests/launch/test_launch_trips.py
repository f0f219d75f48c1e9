"""Trips are typed events end to end: a real lockstep run whose safety layer trips (an over-speed
limit no standing robot can keep) records the trip with its `trips` flag and a detail free of any
marker, its run folder's summary says "fault" naming the trip's kind, and the deploy's preflight
refuses a dry run with those events naming it; a run without a trip completes. An IK that stops
finding solutions ends `g1 launch` as such a fault too (before issue 26's fail-soft IK it ended the
run with `g1 launch: error: daqp found no IK step ...` and no summary)."""

from __future__ import annotations

import dataclasses
import json

import pytest

from g1_control.deploy.preflight import FAIL, Preflight
from g1_control.launch import runner
from g1_control.launch.schema import Segment, load_launch
from g1_control.report.results import format_summary
from tests.paths import LAUNCH_DIR


def _standing(seconds: float, *overrides: str):
    launch = load_launch(LAUNCH_DIR / "sim_walk.yaml", overrides)
    launch.input.timeline = [Segment(duration_s=seconds, label="stand")]
    launch.output.plot = False
    return launch


@pytest.fixture(scope="module")
def tripped(tmp_path_factory):
    launch = _standing(1.0, "safety.overspeed_factor=0.0001")
    return launch, runner.run(launch, out_root=tmp_path_factory.mktemp("runs"), video=False, progress=False)


def test_a_trip_is_recorded_by_its_type_and_the_run_is_a_fault(tripped):
    _launch, result = tripped
    trips = [e for e in result.events if e["trips"]]
    assert [e["kind"] for e in trips] == ["joint_overspeed"], result.events
    assert "damping" not in trips[0]["detail"] and trips[0]["planned"] is False
    summary = json.loads((result.run_dir / "summary.json").read_text())
    assert summary["status"] == "fault", summary["status"]
    assert summary["end_reason"] == f"joint_overspeed: {trips[0]['detail']}"
    lines = [json.loads(line) for line in (result.run_dir / "events.jsonl").read_text().splitlines()]
    assert any(r.get("kind") == "joint_overspeed" and r.get("trips") is True for r in lines)
    assert "s: joint_overspeed (damping): " in format_summary(result)


def test_the_preflight_refuses_a_dry_run_whose_safety_layer_tripped(tripped, monkeypatch):
    """The run's own events, as the dry run hands them over. (A damped robot then falls, which the
    preflight reports first; the fall is taken out here to reach the trip check with real events.)"""
    launch, result = tripped
    assert result.fell, "a damped standing robot falls"
    monkeypatch.setattr(runner, "run", lambda *a, **k: dataclasses.replace(result, fell=False, fall=None))
    pf = Preflight()
    assert not pf.check_dry_run(launch)
    row = pf.results["dry_run"]
    assert row.status == FAIL and row.reason.startswith("the safety layer tripped in simulation: joint_overspeed: "), \
        row.reason


def test_a_run_without_a_trip_completes(tmp_path):
    result = runner.run(_standing(1.0), out_root=tmp_path, video=False, progress=False)
    assert not any(e["trips"] for e in result.events), result.events
    assert json.loads((result.run_dir / "summary.json").read_text())["status"] == "completed"


class _IKFault:
    """The IK stage's QP finds no step (every solve, the relaxed retries too, NoSolutionFound as from
    daqp's infeasible exit) from the IK stage's `after`-th tick on; the ticks before solve as usual."""

    def __init__(self, monkeypatch, after: int):
        from g1_control.ik.exceptions import NoSolutionFound
        from g1_control.ik.solver import QPSolver
        from g1_control.ik.stage import IKStage

        self.ticks, self.on = 0, False
        stage_solve, qp_solve = IKStage.solve, QPSolver.solve

        def stage(stage_self, reference, q_prev):
            self.ticks += 1
            self.on = self.ticks > after
            return stage_solve(stage_self, reference, q_prev)

        def qp(solver_self, *args, **kwargs):
            if self.on:
                raise NoSolutionFound("daqp found no IK step (exit flag -1: infeasible constraints)")
            return qp_solve(solver_self, *args, **kwargs)

        monkeypatch.setattr(IKStage, "solve", stage)
        monkeypatch.setattr(QPSolver, "solve", qp)


def test_g1_launch_ends_an_ik_without_solutions_as_a_fault_with_no_traceback(tmp_path, monkeypatch, capsys):
    """`g1 launch` with a generator whose references the IK solves (interpolation): the IK fails for good
    after 25 ticks (0.5 s). The run ends as a fault naming the IK's error, not as an exception."""
    from g1_control.cli.main import main

    fault = _IKFault(monkeypatch, after=25)
    code = main(["launch", str(LAUNCH_DIR / "sim_walk.yaml"), "--set", "generator.type=interpolation",
                 "--set", "safety.ik_hold_ticks=2", "--set", "output.plot=false", "--duration", "1.0",
                 "--out", str(tmp_path), "--no-video", "--quiet", "--viewer", "off"])
    out, err = capsys.readouterr()
    assert fault.ticks == 50 and "Traceback" not in out + err and "error" not in err, err
    [run_dir] = [p for p in tmp_path.iterdir() if p.is_dir()]
    summary = json.loads((run_dir / "summary.json").read_text())
    detail = ("the IK found no solution on 3 tracker ticks in a row (safety.ik_hold_ticks 2): "
              "NoSolutionFound: daqp found no IK step (exit flag -1: infeasible constraints)")
    assert summary["status"] == "fault" and summary["end_reason"] == f"ik_failure: {detail}", summary["end_reason"]
    assert "s: ik_failure (damping): " + detail in out
    lines = [json.loads(line) for line in (run_dir / "events.jsonl").read_text().splitlines()]
    kinds = [(r["kind"], r["trips"], round(r["t_s"], 3)) for r in lines if r.get("type") == "safety"]
    assert kinds[:2] == [("ik_hold", False, 0.5), ("ik_failure", True, 0.54)], kinds
    assert code == 1  # the damped robot then falls (g1 launch exits 1 on a fall)


# -- g1 launch's exit status: clean 0, a trip without a fall 3, a fall 1 ------------------------------------
def _g1_launch(tmp_path, *extra: str) -> tuple[int, dict]:
    from g1_control.cli.main import main

    code = main(["launch", str(LAUNCH_DIR / "sim_walk.yaml"), "--set", "generator.type=interpolation",
                 "--set", "output.plot=false", "--out", str(tmp_path), "--no-video", "--quiet", "--viewer", "off",
                 *extra])
    [run_dir] = [p for p in tmp_path.iterdir() if p.is_dir()]
    return code, json.loads((run_dir / "summary.json").read_text())


def test_g1_launch_exits_0_on_a_clean_run(tmp_path):
    code, summary = _g1_launch(tmp_path, "--duration", "1.0")
    assert summary["status"] == "completed" and not summary["fell"], summary["end_reason"]
    assert code == 0


def test_g1_launch_exits_3_on_a_trip_without_a_fall(tmp_path, monkeypatch):
    """The IK fails for good from its 26th tick: ik_failure trips at 0.54 s and the run ends at 0.7 s,
    too soon for the damped robot to fall. Before, this exited 0 like a clean run."""
    from g1_control.cli.launch_cmd import EXIT_TRIPPED

    _IKFault(monkeypatch, after=25)
    code, summary = _g1_launch(tmp_path, "--set", "safety.ik_hold_ticks=2", "--duration", "0.7")
    assert summary["status"] == "fault" and summary["end_reason"].startswith("ik_failure: "), summary["end_reason"]
    assert not summary["fell"], summary["fall"]
    assert code == EXIT_TRIPPED == 3


def test_the_exit_status_puts_a_fall_before_a_trip_and_a_trip_before_a_missed_goal(tripped):
    """On the real tripped run's result (a joint over-speed trip, then the damped robot falls), with its
    fall, trip and goals taken out or added one at a time."""
    from g1_control.cli.launch_cmd import EXIT_FAILED, EXIT_OK, EXIT_TRIPPED, exit_status

    _launch, result = tripped
    no_fall = dataclasses.replace(result, fell=False, fall=None)
    not_a_trip = [dict(e, trips=False) for e in result.events]
    planned = [dict(e, planned=True) for e in result.events]
    missed = {"goals": [{"name": "pick box", "status": "timeout"}]}
    reached = {"goals": [{"name": "pick box", "status": "reached"}]}
    assert exit_status(result) == EXIT_FAILED  # a fall, whatever tripped before it
    assert exit_status(no_fall) == EXIT_TRIPPED
    assert exit_status(dataclasses.replace(no_fall, extra=missed)) == EXIT_TRIPPED
    assert exit_status(dataclasses.replace(no_fall, events=not_a_trip, extra=missed)) == EXIT_FAILED
    assert exit_status(dataclasses.replace(no_fall, events=not_a_trip, extra=reached)) == EXIT_OK
    assert exit_status(dataclasses.replace(no_fall, events=planned)) == EXIT_OK  # a planned ending is no fault
    assert (EXIT_OK, EXIT_FAILED, EXIT_TRIPPED) == (0, 1, 3)


def test_g1_say_exits_as_g1_launch_does_fall_first_then_trip_then_a_missed_step(tripped):
    """g1 say's exit status on the same real tripped run (before, a trip without a fall exited 1, as a
    missed step does, not 3)."""
    from g1_control.cli.launch_cmd import EXIT_FAILED, EXIT_OK, EXIT_TRIPPED
    from g1_control.cli.say_cmd import say_exit_status

    _launch, result = tripped
    no_fall = dataclasses.replace(result, fell=False, fall=None)
    not_a_trip = [dict(e, trips=False) for e in result.events]
    done = {"finished": True, "steps": [{"status": "completed", "verdict": {"ok": True}}]}
    missed = {"finished": True, "steps": [{"status": "completed", "verdict": {"ok": False}}]}
    unfinished = {"finished": False, "steps": [{"status": "completed"}]}
    assert say_exit_status(result, done) == EXIT_FAILED  # a fall, whatever tripped before it
    assert say_exit_status(no_fall, done) == EXIT_TRIPPED
    assert say_exit_status(no_fall, missed) == EXIT_TRIPPED
    clean = dataclasses.replace(no_fall, events=not_a_trip)
    assert say_exit_status(clean, missed) == EXIT_FAILED
    assert say_exit_status(clean, unfinished) == EXIT_FAILED
    assert say_exit_status(clean, done) == EXIT_OK
