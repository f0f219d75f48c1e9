"""The deploy session's end of run (issue 26: the mutation run's loop group) on a stand-in clock: the
control phase of `g1 deploy` (_RobotControl: the launch file's loop built around the deploy state
machine, run, ended in damping, reported), driven step by step as session._control drives it, with
the wall clock replaced by a clock the test advances (the loop's scheduler sleeps on it; the session
and the state machine read it) and the robot behind its link by a stand-in that stamps its states
with that clock.

Nothing here waits on the wall clock, so these run under mutmut on a loaded host, where the deploys
over DDS (test_deploy_runtime_trips.py, test_deploy_run_folder.py, ...) miss their deadlines. What is
asserted is what the operator, the link and the run folder see: damping on the link at the end of
every run, the states and their times, the report's end reason, fault flag, safety events, control
window and loop figures, the run folder's status, the signal path (a real SIGINT or SIGTERM sent to
this process inside the loop), and errors that end a run."""

from __future__ import annotations

import dataclasses
import json
import os
import signal
import types
from pathlib import Path

import numpy as np
import pytest
import yaml
from deploy_test_helpers import ROOT, write_launch

from g1_control.deploy import session
from g1_control.deploy.session import DeployOptions, DeployReport, _open_input, _RobotControl
from g1_control.errors import InvalidCommandError, RobotNotConnectedError
from g1_control.hardware.link_backend import LinkStats
from g1_control.interfaces import Backend, InputDevice
from g1_control.launch.schema import load_launch
from g1_control.loop import control_loop
from g1_control.robot import g1
from g1_control.types import Command, MotorCommand, RobotState

SPECS = ROOT / "g1_control" / "policies" / "specs"
T0 = 1000.0
"""The stand-in clock's reading when a test starts (a monotonic clock is never near 0)."""
LIMIT_S = 60.0
"""A run still going this long after T0 has failed to end (a test fails instead of hanging)."""
TIMING = {"ramp_s": 2.0, "auto_start_s": 0.5, "auto_run_s": 1.0, "min_hold_s": 0.5, "exit_damping_s": 0.5}
"""The deploy's timing in these tests: with --yes, ramp at T0 + 0.5, hold at + 2.5, control at + 3.5."""


class Clock:
    """The host's monotonic clock, advanced only by sleeping (the loop's compute takes no time here)
    and by stalls (the host held up: the first sleep past `at` overruns by `seconds`)."""

    def __init__(self, t0: float = T0):
        self.t = t0
        self.slept: list[float] = []
        self.stalls: list[tuple[float, float]] = []

    def monotonic(self) -> float:
        return self.t

    def sleep(self, seconds: float) -> None:
        assert self.t < T0 + LIMIT_S, f"the run did not end within {LIMIT_S} s"
        self.slept.append(seconds)
        self.t += seconds
        while self.stalls and self.t >= self.stalls[0][0]:
            self.t += self.stalls.pop(0)[1]


class StandInLink(Backend):
    """The robot behind its link as the host sees it: a G1 standing on its default pose whose IMU
    reports a yaw rate growing with time (so every logged tick differs), states stamped with the
    host's clock on arrival (a new tick each read); the latest command written, or damp()'s damping,
    is what streams to the motors. Link counters as LinkBackend.stats() reports them."""

    lockstep = False
    release_motion_service = False
    released_modes: tuple[str, ...] = ()
    expected_mode_machine = 5

    def __init__(self, clock: Clock, damping_kd: float):
        self.clock, self.damping_kd = clock, damping_kd
        self.tick = 0
        self.streaming: MotorCommand | None = None
        self.sent: list[tuple[float, MotorCommand]] = []
        self.damped_at: list[float] = []
        self.hot_at: float | None = None
        """From this time on, the waist yaw motor reports 110 degC."""
        self.lost_at: float | None = None
        """From this time on, no state arrives (read_state raises, as LinkBackend does)."""
        self.refuses_at: float | None = None
        """From this time on, write_command raises (the link refuses the command, as LinkBackend does)."""
        self.holds = (0, 0)
        """(times a command outlived its life, hold-form messages sent), as LinkBackend counts them."""

    def reset(self) -> RobotState:
        return self.read_state()

    def read_state(self) -> RobotState:
        t = self.clock.t
        if self.lost_at is not None and t >= self.lost_at:
            raise RobotNotConnectedError("no valid LowState from the robot yet on the stand-in link")
        self.tick += 1
        state = RobotState(t_s=t, q_rad=g1.DEFAULT_Q_RAD.copy(), tick=self.tick, mode_machine=5,
                           motor_temperature_c=np.full(g1.NUM_JOINTS, 40.0))
        state.imu_gyro_radps[2] = 0.05 * (t - T0)
        if self.hot_at is not None and t >= self.hot_at:
            state.motor_temperature_c[12] = 110.0
        return state

    def write_command(self, command: MotorCommand) -> None:
        if self.refuses_at is not None and self.clock.t >= self.refuses_at:
            raise InvalidCommandError("MotorCommand.q_rad has shape (23,); expected (29,)")
        self.streaming = dataclasses.replace(command, q_rad=command.q_rad.copy(), kp=command.kp.copy(),
                                             kd=command.kd.copy())
        self.sent.append((self.clock.t, self.streaming))

    def damp(self) -> None:
        self.streaming = MotorCommand.damping(self.damping_kd)
        self.damped_at.append(self.clock.t)

    def stats(self) -> LinkStats:
        return LinkStats(commands_sent=len(self.sent), states_received=self.tick, bad_crc=0, malformed=0,
                         bad_frames=0, state_rate_hz=50.0, command_rate_hz=500.0, command_period_p99_s=0.002,
                         last_state_age_s=0.0, command_ttl_s=0.06, holds=self.holds[0], commands_held=self.holds[1])

    def streams_damping(self) -> bool:
        s = self.streaming
        return s is not None and not np.any(s.kp) and bool(np.all(s.kd == self.damping_kd))

    def sent_between(self, start: float, end: float) -> list[MotorCommand]:
        return [c for t, c in self.sent if start <= t < end]

    def close(self) -> None:
        pass


class Remote(InputDevice):
    """The operator's remote: `presses` [(time, button)]; `at` = (time, what): a signal number sent to
    this process, or an exception raised from the poll (as a device's driver may)."""

    def __init__(self, presses=(), at: tuple[float, int | BaseException] | None = None):
        self.presses, self.at = sorted(presses), at

    def poll(self, now_s: float) -> Command:
        if self.at is not None and now_s >= self.at[0]:
            what, self.at = self.at[1], None
            if isinstance(what, BaseException):
                raise what
            os.kill(os.getpid(), what)  # its handler runs in this (the main) thread, inside the loop
        buttons = set()
        while self.presses and now_s >= self.presses[0][0]:
            buttons.add(self.presses.pop(0)[1])
        return Command(buttons=frozenset(buttons))

    def button_chords(self, action: str) -> list[str]:
        return {"start": ["start"], "run": ["A"], "stop": ["B"], "estop": ["L1+R1"]}.get(action, [])


@pytest.fixture
def clock(monkeypatch) -> Clock:
    clock = Clock()
    fake = types.SimpleNamespace(monotonic=clock.monotonic, sleep=clock.sleep)
    monkeypatch.setattr(session, "time", fake)
    monkeypatch.setattr(control_loop, "time", fake)
    return clock


@dataclasses.dataclass
class Run:
    control: _RobotControl
    link: StandInLink
    report: DeployReport
    lines: list[str]
    error: Exception | None
    raised: BaseException | None = None
    """What finish() raised (the error that ended the run, after the report)."""

    def summary(self) -> dict:
        return json.loads((Path(self.report.run_dir or "") / "summary.json").read_text())

    def log(self) -> dict:
        with np.load(Path(self.report.run_dir or "") / "log.npz") as data:
            return {k: data[k] for k in data.files}

    def transitions(self) -> list[tuple[float, str, str, str]]:
        return [(round(t["t_s"] - T0, 6), t["from"], t["to"], t["reason"]) for t in self.report.transitions]


def _run(tmp_path, clock: Clock, changes: dict | None = None, device=None, yes: bool = True,
         duration_s: float | None = 5.0, prepare=None, finish: bool = True) -> Run:
    """The control phase of a deploy as session._control runs it (build_loop, open_run_folder, run, finish)
    on the stand-in clock and link. `device`: the operator's (None: the launch file's input; a function
    of the launch file: made from it); `prepare(control, link)` runs before run()."""
    changes = dict(changes or {})
    launch = load_launch(write_launch(tmp_path, {**changes, "deploy": {**TIMING, **changes.get("deploy", {})}}))
    link = StandInLink(clock, launch.safety.damping_kd)
    if callable(device):
        device = device(launch)
    if device is None:
        device, why = _open_input(launch, link, None)
        assert why is None, why
    report, lines = DeployReport(launch="launch.yaml"), []
    control = _RobotControl(launch, link, device, DeployOptions(yes=yes, duration_s=duration_s, out_root=tmp_path),
                            report, lines.append)
    control.build_loop()
    control.loop.scheduler.clock, control.loop.scheduler.sleep = clock.monotonic, clock.sleep
    control.open_run_folder()
    if prepare is not None:
        prepare(control, link)
    run = Run(control, link, report, lines, control.run())
    if finish:
        try:
            control.finish(run.error)
        except Exception as exc:
            run.raised = exc
    return run


def _window_mean(log: dict, column: str, start: float, end: float) -> list[float]:
    t = T0 + log["t_s"]
    return log[column][(t >= start) & (t < end)].mean(axis=0).tolist()


def test_a_run_to_the_end_of_its_control_time_ends_planned_in_damping_and_is_reported(tmp_path, clock):
    run = _run(tmp_path, clock)
    assert run.error is None and run.raised is None
    assert run.transitions() == [(0.5, "zero_torque", "ramp", "start (--yes)"),
                                 (2.5, "ramp", "hold", "default pose reached (2.0 s ramp)"),
                                 (3.5, "hold", "control", "run (--yes)"),
                                 (8.5, "control", "damping", "control time over (5.0 s)")]
    assert run.report.sequence == ["zero_torque", "ramp", "hold", "control", "damping"]
    # every transition is said as it happens, in the session's time
    assert "[   0.50 s] zero_torque -> ramp: start (--yes)" in run.lines
    assert "[   8.50 s] control -> damping: control time over (5.0 s)" in run.lines
    # damping streamed exit_damping_s after the trip, then the link damped once more at the end
    assert clock.t == pytest.approx(T0 + 9.0, abs=1e-9) and run.link.damped_at == [clock.t]
    assert run.link.streams_damping()
    assert run.report.end_reason == "control time over (5.0 s, launch duration_s)" and not run.report.fault
    assert run.report.safety_events == [{"t_s": pytest.approx(T0 + 8.5), "kind": "estop",
                                         "detail": "control time over (5.0 s, launch duration_s)", "trips": True,
                                         "planned": True}]
    assert run.report.link == dataclasses.asdict(run.link.stats())
    assert not any("hold form" in line for line in run.lines), "no command was held: nothing is said about it"
    summary = run.summary()
    assert (summary["status"], summary["end_reason"]) == ("completed", run.report.end_reason)
    assert summary["transitions"] == json.loads(json.dumps(run.report.transitions))


def test_the_report_measures_control_over_its_steady_window_after_the_gaits_first_2_s(tmp_path, clock):
    run = _run(tmp_path, clock)
    c, log = run.report.control, run.log()
    assert c["duration_s"] == pytest.approx(5.0) and c["steady_window_s"] == pytest.approx(3.0)
    # the timeline stands for 1 s, then walks at 0.5 m/s: the steady window (from 2 s in) sees the walk only
    assert c["command_mean"] == pytest.approx([0.5, 0.0, 0.0])
    # the IMU's yaw rate grows with time: the mean is over exactly [control start + 2 s, control end)
    assert c["velocity_est_mean"] == pytest.approx(_window_mean(log, "velocity_est", T0 + 5.5, T0 + 8.5), abs=1e-12)
    assert c["velocity_est_mean"] != pytest.approx(_window_mean(log, "velocity_est", T0 + 5.5, T0 + 8.52), abs=1e-6)
    assert c["velocity_est_mean"] != pytest.approx(_window_mean(log, "velocity_est", T0 + 5.52, T0 + 8.5), abs=1e-6)
    assert c["velocity_est_mean"][2] == pytest.approx(0.05 * 7.0, abs=0.02)
    assert list(c["upper_body_vs_plan"]) == ["default"]
    # the upper body over the whole of control, [start, end): 250 ticks of 20 ms
    assert c["upper_body_vs_plan"]["default"]["seconds"] == pytest.approx(5.0, abs=1e-9)


@pytest.mark.parametrize("control_s", [3.0, 4.0, 4.5])
def test_a_short_control_phase_is_measured_whole_and_a_longer_one_from_2_s_in(tmp_path, clock, control_s):
    """Up to 4 s of control (4 s included: on this clock control lasts exactly 4.0 s) is measured whole."""
    run = _run(tmp_path, clock, duration_s=control_s)
    c, log = run.report.control, run.log()
    assert c["duration_s"] == control_s  # exactly: the ticks of 20 ms fall on whole and half seconds here
    start, end = T0 + 3.5, T0 + 3.5 + control_s
    steady_from = start + (2.0 if control_s > 4.0 else 0.0)
    assert c["duration_s"] == pytest.approx(control_s) and c["steady_window_s"] == pytest.approx(end - steady_from)
    assert c["command_mean"] == pytest.approx(_window_mean(log, "command", steady_from, end), abs=1e-12)
    assert c["velocity_est_mean"] == pytest.approx(_window_mean(log, "velocity_est", steady_from, end), abs=1e-12)
    if control_s < 4.0:  # the standing second is in the window
        assert 0.2 < c["command_mean"][0] < 0.45


def test_the_loops_figures_in_the_report_are_the_schedulers_after_host_stalls(tmp_path, clock):
    # the host stalls in control: the next tick ends 10, 45 and 70 ms late (the last two past the next
    # tick's deadline too: 2 and 3 whole ticks are skipped), then 8 ticks end 5 ms late
    clock.stalls = [(T0 + 4.0, 0.03), (T0 + 5.0, 0.065), (T0 + 6.0, 0.09),
                    *((T0 + 6.2 + 0.1 * k, 0.025) for k in range(8))]
    run = _run(tmp_path, clock)
    s, loop = run.control.loop.scheduler, run.report.loop
    assert loop == {"deadline_misses": s.deadline_misses, "ticks": s.tick_index,
                    "tick_p99_us": s.report()["tick"]["p99_us"], "stages_us": s.report(),
                    "lateness_p99_ms": pytest.approx(5.0),
                    "lateness_max_ms": pytest.approx(70.0), "misses_over_period": 2, "skipped_ticks": 5,
                    "clamped_commands": run.control.safety.clamps.commands}
    assert loop["deadline_misses"] == 11 and loop["ticks"] == 450
    assert "while_planning" not in loop
    assert run.lines[-1].startswith("loop: 450 ticks, 11 deadline misses (worst 70.0 ms late, p99 5.0 ms; 5 ticks "
                                    "skipped after stalls)")


def test_commands_the_link_held_through_stalls_are_reported_and_said(tmp_path, clock):
    run = _run(tmp_path, clock, prepare=lambda control, link: setattr(link, "holds", (2, 37)))
    assert (run.report.link["holds"], run.report.link["commands_held"]) == (2, 37)
    assert ("lowcmd hold form: 2 time(s) the loop stalled past the command's 60 ms life; 37 messages held the pose "
            "without feedforward torque or velocity targets") in run.lines


def test_lateness_while_plans_were_made_is_reported_for_the_generators_plan_windows(tmp_path, clock):
    def plans(control, link):
        # a goal planner's windows (GoalExecutor.plan_windows, in the states' clock), 0.2 s from control start
        control.loop.generator.plan_windows = [("approach box", T0 + 4.0, T0 + 4.2)]

    clock.stalls = [(T0 + 4.1, 0.03)]  # one tick in the window ends 10 ms late
    run = _run(tmp_path, clock, prepare=plans)
    planning = run.report.loop["while_planning"]
    assert planning == session.lateness_while(run.log(), run.control.t_loop0, [("approach box", T0 + 4.0, T0 + 4.2)],
                                              0.02, run.control.safety.config.overrun_lateness_s)
    assert (planning["plans"], planning["rows"], planning["rows_late"]) == (1, 12, 1)
    assert planning["windows"] == [{"what": "approach box", "start_s": pytest.approx(4.0), "seconds": pytest.approx(0.2)}]


@pytest.mark.parametrize("signum, name", [(signal.SIGTERM, "SIGTERM"), (signal.SIGINT, "SIGINT")])
def test_a_signal_in_control_damps_at_once_and_ends_the_run_planned_as_interrupted(tmp_path, clock, signum, name):
    before = {s: signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM)}
    run = _run(tmp_path, clock, device=Remote(at=(T0 + 4.5, signum)))
    assert run.error is None
    assert {s: signal.getsignal(s) for s in before} == before, "the session's signal handlers were not removed"
    # the handler damps the link itself, then the run's end damps again, after exit_damping_s more of it
    assert run.link.damped_at == [pytest.approx(T0 + 4.5), pytest.approx(T0 + 4.5)]
    assert clock.slept[-1] == 0.5 and clock.t == pytest.approx(T0 + 5.0) and run.link.streams_damping()
    assert run.transitions()[-1] == (4.5, "control", "damping", f"estop: {name} received")
    assert run.report.safety_events == [{"t_s": pytest.approx(T0 + 4.5), "kind": "estop",
                                         "detail": f"{name} received", "trips": True, "planned": True}]
    assert run.report.end_reason == f"{name} received" and not run.report.fault
    assert run.summary()["status"] == "interrupted"
    assert run.report.control["duration_s"] == pytest.approx(1.0)


def test_the_operators_stop_damps_and_is_a_planned_end(tmp_path, clock):
    remote = Remote([(T0 + 0.2, "start"), (T0 + 2.9, "run"), (T0 + 4.0, "stop")])
    run = _run(tmp_path, clock, device=remote, yes=False, duration_s=None)
    assert run.transitions() == [(0.2, "zero_torque", "ramp", "operator start"),
                                 (2.2, "ramp", "hold", "default pose reached (2.0 s ramp)"),
                                 (2.9, "hold", "control", "operator run"),
                                 (4.0, "control", "damping", "operator stop")]
    assert "holding the default pose: press A to start the policy" in run.lines
    assert run.report.end_reason == "operator stop" and not run.report.fault
    assert run.summary()["status"] == "completed" and run.link.streams_damping()
    assert clock.t == pytest.approx(T0 + 4.5)


def test_the_ramp_and_hold_stream_the_walking_policys_own_pose_and_gains(tmp_path, clock):
    # the shipped ppo's pose and gains are the robot's: a spec of the same network with its own pose
    # (knees 0.05 rad deeper) and gains (1 % stiffer: inside what the ONNX metadata check allows)
    data = yaml.safe_load((SPECS / "holosoma_loco_ppo.yaml").read_text())
    pose, kp, kd = g1.DEFAULT_Q_RAD.copy(), g1.KP_DEFAULT * 1.01, g1.KD_DEFAULT * 1.01
    pose[[3, 9]] += 0.05
    data.update(name="ppo-own-pose", default_q=pose.tolist(), gains={"kp": kp.tolist(), "kd": kd.tolist()})
    (tmp_path / "own_pose.yaml").write_text(yaml.safe_dump(data))
    run = _run(tmp_path, clock, {"tracker": {"policy": str(tmp_path / "own_pose.yaml")}},
               device=Remote([(T0 + 0.2, "start"), (T0 + 3.0, "stop")]), yes=False)
    hold = run.link.sent_between(T0 + 2.3, T0 + 3.0)
    assert hold and all(np.allclose(c.q_rad, pose) and np.allclose(c.kp, kp) and np.allclose(c.kd, kd) for c in hold)
    assert run.transitions()[-1] == (3.0, "hold", "damping", "operator stop")


def test_a_tracker_without_a_policy_spec_ramps_to_the_robots_default_pose_and_gains(tmp_path, clock):
    run = _run(tmp_path, clock, {"tracker": {"type": "wbc", "policy": None, "velocity_correction": None},
                                 "rates": {"lowlevel_hz": 100, "tracker_hz": 100}},
               device=Remote([(T0 + 0.2, "start"), (T0 + 3.0, "stop")]), yes=False)
    hold = run.link.sent_between(T0 + 2.3, T0 + 3.0)
    assert hold and all(np.array_equal(c.q_rad, g1.DEFAULT_Q_RAD) and np.array_equal(c.kp, g1.KP_DEFAULT)
                        and np.array_equal(c.kd, g1.KD_DEFAULT) for c in hold)


def test_a_trip_in_control_is_a_fault_that_ends_in_damping(tmp_path, clock):
    def hot(control, link):
        link.hot_at = T0 + 4.0

    run = _run(tmp_path, clock, prepare=hot)
    trip = [e for e in run.report.safety_events if e["trips"]]
    assert [e["kind"] for e in trip] == ["over_temperature"] and trip[0]["t_s"] == pytest.approx(T0 + 4.0)
    assert run.report.end_reason == trip[0]["detail"] and run.report.fault
    # the loop sends damping from the trip's tick on; the state machine follows it before the next tick
    assert run.link.sent_between(T0 + 4.0, T0 + 4.02)[0].kp.max() == 0
    assert run.transitions()[-1] == (4.02, "control", "damping", f"over_temperature: {trip[0]['detail']}")
    assert run.summary()["status"] == "fault" and run.link.streams_damping()
    assert clock.t == pytest.approx(T0 + 4.52) and run.link.damped_at == [clock.t]
    # half a second of control: measured whole
    assert run.report.control["duration_s"] == pytest.approx(0.52)
    assert run.report.control["steady_window_s"] == pytest.approx(0.52)


def test_an_error_in_control_damps_ends_the_run_as_an_error_and_is_raised_after_the_report(tmp_path, clock):
    def lose(control, link):
        link.lost_at = T0 + 4.0

    run = _run(tmp_path, clock, prepare=lose)
    assert isinstance(run.error, RobotNotConnectedError)
    detail = f"error: {run.error}"
    assert run.report.safety_events[-1] == {"t_s": pytest.approx(T0 + 4.0), "kind": "estop", "detail": detail,
                                            "trips": True, "planned": False}
    assert run.transitions()[-1] == (4.0, "control", "damping", f"estop: {detail}")
    assert run.report.end_reason == detail and run.report.fault
    assert run.link.damped_at == [pytest.approx(T0 + 4.0)] and clock.t == pytest.approx(T0 + 4.5)
    assert run.summary()["status"] == "error" and run.link.streams_damping()
    assert run.raised is run.error, "finish raises the error that ended the run, after the report is written"


def test_a_run_that_ends_with_no_trip_and_no_signal_of_its_own_is_reported_as_a_fault_exit(tmp_path, clock):
    run = _run(tmp_path, clock, device=Remote(at=(T0 + 4.5, KeyboardInterrupt())))
    assert run.error is None and run.report.safety_events == []
    assert run.transitions()[-1] == (4.5, "control", "damping", "exit")
    assert clock.slept[-1] == 0.5 and run.link.streams_damping()
    assert run.report.end_reason == "exit" and run.report.fault and run.summary()["status"] == "fault"


def test_an_unexpected_exception_still_ends_in_damping_and_propagates(tmp_path, clock):
    before = signal.getsignal(signal.SIGTERM)
    with pytest.raises(RuntimeError, match="driver crashed"):
        _run(tmp_path, clock, device=Remote(at=(T0 + 1.0, RuntimeError("driver crashed"))), finish=False)
    assert signal.getsignal(signal.SIGTERM) == before
    assert clock.t == pytest.approx(T0 + 1.5), "damping streamed exit_damping_s before the link closes"



@pytest.mark.parametrize("instruction, finished", [("wait 1 second", True), ("wait 10 seconds", False)])
def test_a_behaviour_programs_steps_and_whether_it_finished_go_into_the_report(tmp_path, clock, instruction,
                                                                             finished):
    from g1_control.program import parse_instruction
    from g1_control.program.device import ProgramInput, record_dict

    def program(launch):  # as deploy() wraps the operator's device
        return ProgramInput(parse_instruction(instruction), launch.program_world(), pose="estimator",
                            start_delay_s=0.5, operator=Remote())

    run = _run(tmp_path, clock, device=program, duration_s=3.0)
    device = run.control.device
    assert isinstance(device, ProgramInput)
    assert run.report.control["program"] == {"steps": [record_dict(r) for r in device.records], "finished": finished}
    assert len(run.report.control["program"]["steps"]) == int(finished)
    assert run.summary()["control"]["program"]["finished"] is finished


def test_a_control_phase_without_a_logged_tick_reports_no_means(tmp_path, clock):
    """The link refuses the first command of control (the tick control starts, before it is logged): the
    run ends in damping at that instant, and the report has no mean of an empty window."""
    def refuse(control, link):
        link.refuses_at = T0 + 3.5

    run = _run(tmp_path, clock, prepare=refuse)
    assert isinstance(run.error, InvalidCommandError) and run.raised is run.error
    assert run.transitions()[-2:] == [(3.5, "hold", "control", "run (--yes)"),
                                      (3.5, "control", "damping", f"estop: error: {run.error}")]
    c = run.report.control
    assert (c["duration_s"], c["steady_window_s"]) == (0.0, 0.0)
    assert c["velocity_est_mean"] is None and c["command_mean"] is None and c["upper_body_vs_plan"] == {}


def test_goals_whose_turn_never_came_are_reported_and_written_to_the_run_folder(tmp_path, clock):
    """launch/sim2sim_goals.yaml (the layer tracker; its goals planned in the planner's own process)
    stopped after 1 s of control, before the timeline's first goal (at 2 s)."""
    run = _run(tmp_path, clock, yaml.safe_load((ROOT / "launch" / "sim2sim_goals.yaml").read_text()), duration_s=1.0)
    assert [(g["goal_id"], g["status"], g["message"]) for g in run.report.goals] == [
        (f"seg{i}.0", "not started", "control ended before the goal's turn came") for i in (1, 2, 3)]
    lines = (Path(run.report.run_dir or "") / "events.jsonl").read_text().splitlines()
    written = [json.loads(line) for line in lines]
    assert [{k: v for k, v in e.items() if k != "t_run_s"} for e in written if e["type"] == "goal"] == [
        {"type": "goal", **g} for g in run.report.goals]
    assert run.summary()["goals"] == run.report.goals


def test_an_ik_that_stops_finding_solutions_holds_then_trips_and_the_deploy_damps(tmp_path, clock, monkeypatch):
    """Issue 26, fail-soft IK: a generator whose references the IK solves (interpolation); from T0 + 4.0
    the IK's QP finds no step (every solve, the relaxed retries too). Two ticks hold the last good
    reference (safety.ik_hold_ticks 2), the third trips: a typed ik_failure fault, damping on the link,
    the state machine in damping, not an error that ends the run."""
    from g1_control.ik.exceptions import NoSolutionFound
    from g1_control.ik.solver import QPSolver

    qp_solve = QPSolver.solve

    def failing_from_4_s(solver, *args, **kwargs):
        if clock.t >= T0 + 4.0:
            raise NoSolutionFound("daqp found no IK step (exit flag -1: infeasible constraints)")
        return qp_solve(solver, *args, **kwargs)

    monkeypatch.setattr(QPSolver, "solve", failing_from_4_s)
    run = _run(tmp_path, clock, {"generator": {"type": "interpolation"}, "safety": {"ik_hold_ticks": 2}})
    assert run.error is None and run.raised is None
    events = [(e["kind"], e["trips"], round(e["t_s"] - T0, 6)) for e in run.report.safety_events]
    assert events == [("ik_hold", False, 4.0), ("ik_failure", True, 4.04)], events
    detail = ("the IK found no solution on 3 tracker ticks in a row (safety.ik_hold_ticks 2): "
              "NoSolutionFound: daqp found no IK step (exit flag -1: infeasible constraints)")
    assert run.report.safety_events[-1]["detail"] == detail
    assert run.report.end_reason == detail and run.report.fault
    assert run.link.sent_between(T0 + 4.0, T0 + 4.04)[-1].kp.max() > 0  # held: still under control
    assert run.link.sent_between(T0 + 4.04, T0 + 4.06)[0].kp.max() == 0  # tripped: damping from that tick
    assert run.transitions()[-1] == (4.06, "control", "damping", f"ik_failure: {detail}")
    assert run.summary()["status"] == "fault" and run.link.streams_damping()
