"""One `g1 deploy` session: preflight, then the state machine on the control loop, then damping.

    report = deploy(Path("launch/robot.yaml"), DeployOptions())

Nothing is sent to the robot before the preflight passed: opening the link only listens, and the
robot's built-in motion service is released only after the checklist (a refused deploy leaves the
robot as it found it). From the first command on, the loop's SafetyFilter vets everything, and
every way out (operator stop, e-stop, fault, SIGINT/SIGTERM, end of the control time, an error)
ends in damping streamed for DeployConfig.exit_damping_s before the link closes.
"""

from __future__ import annotations

import dataclasses
import json
import logging
import math
import signal
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from g1_control.deploy.preflight import CHECKS, FAIL, OPTIONAL_CHECKS, Preflight
from g1_control.deploy.state_machine import DeployState, DeployTracker, OperatorButtons, Transition
from g1_control.errors import G1ControlError, LaunchFileError
from g1_control.hardware.links.network import LOOPBACK
from g1_control.interfaces import InputDevice, Tracker
from g1_control.launch.schema import LaunchFile
from g1_control.loop.priority import frozen_heap, realtime
from g1_control.report.run_folder import RunFolder
from g1_control.robot import g1
from g1_control.safety import SafetyFilter

if TYPE_CHECKING:
    from g1_control.hardware.link_backend import LinkBackend

log = logging.getLogger("g1_control.deploy")

ROBOT_CHECKS = ("variant", "state_stream", "peers", "motion_service", "imu_upright", "joint_limits", "temperatures",
                "battery")


@dataclass
class DeployOptions:
    yes: bool = False
    """Answer start and run automatically once the preflight passed (unattended sim2sim)."""
    overrides: frozenset[str] = frozenset()
    release_motion_service: bool | None = None
    """None: the launch file's backend.release_motion_service."""
    interface: str | None = None
    domain: int | None = None
    partition: str | None = None
    duration_s: float | None = None
    """Length of the control phase (None: the launch file's duration_s, or until stopped)."""
    preflight_only: bool = False
    program: Any = None
    """A behaviour program (g1_control.program.Program) that drives the robot once control starts;
    the operator device keeps its buttons (start, run, stop, e-stop). Dry-run in MuJoCo first."""
    program_text: str = ""
    """The English instruction `program` was parsed from: it is shown and must be confirmed (y) on
    a robot; --yes answers only on sim2sim."""
    out_root: Path | None = None
    """Where the run folder goes (None: the launch file's output.dir)."""


@dataclass
class DeployReport:
    launch: str
    refused: bool = False
    preflight: list[dict] = field(default_factory=list)
    overridden: list[str] = field(default_factory=list)
    sequence: list[str] = field(default_factory=list)
    transitions: list[dict] = field(default_factory=list)
    end_reason: str = ""
    fault: bool = False
    safety_events: list[dict] = field(default_factory=list)
    released_modes: list[str] = field(default_factory=list)
    link: dict = field(default_factory=dict)
    control: dict = field(default_factory=dict)
    loop: dict = field(default_factory=dict)
    chain: dict = field(default_factory=dict)
    """The loop's stages (g1_control/launch/builder.py), the same the preflight's dry run ran."""
    dry_run_chain: dict = field(default_factory=dict)
    run_dir: str | None = None
    """The run folder (per-tick log, events, summary), written as the deploy went."""
    goals: list[dict] = field(default_factory=list)
    """Every goal's status and message, as the execution layer reports them (report/outcomes.py
    goal_reports: no ground truth on a robot), including the launch file's goals that never started."""
    localisation: dict = field(default_factory=dict)
    """What goals and programs steered by (the robot's own estimate: estimation/localiser.py): its last
    pose in the scene frame and, with an external pose input, how many poses were accepted and refused why."""
    error: str = ""
    """The error that ended the deploy, if one did (set by `g1 deploy`, which writes --json whatever happened)."""

    def to_json(self) -> str:
        return json.dumps(dataclasses.asdict(self), indent=2, default=float)


def _say(text: str) -> None:
    print(text, flush=True)


def _keys_for(device: InputDevice, action: str) -> str:
    return " or ".join(device.button_chords(action))


def _apply_cli(launch: LaunchFile, options: DeployOptions) -> None:
    b = launch.backend
    if options.interface is not None:
        b.interface = options.interface
    if options.domain is not None:
        b.domain = options.domain
    if options.partition is not None:
        b.partition = options.partition
    if options.release_motion_service is not None:
        b.release_motion_service = options.release_motion_service
    b.validate("backend")
    simulated = (b.type == "unitree_dds" and b.interface == LOOPBACK) or (b.type == "can" and b.can_interface == "virtual")
    if options.yes and not simulated:
        raise LaunchFileError("--yes answers start and run with nobody watching; it is only for g1 sim-robot on "
                              f"'{LOOPBACK}' (or a virtual CAN bus). On a robot the operator presses start and run")


def _open_input(launch: LaunchFile, backend, spec):
    """(device, None) or (None, why it cannot be opened)."""
    from g1_control.launch.builder import command_limits, timeline_of
    from g1_control.launch.inputs import make_input

    kind = launch.input.type
    limits = command_limits(launch, spec.command_limits if spec is not None else None)
    try:
        device = make_input(launch, timeline_of(launch), limits=limits,
                            state_source=backend.read_state if backend is not None else None)
    except G1ControlError as exc:
        return None, f"{kind} cannot be opened: {exc}"
    except OSError as exc:
        return None, f"{kind} cannot be opened: {exc}"
    return device, None


def _confirm_program(launch: LaunchFile, options: DeployOptions, say, ask) -> bool:
    """Show the program; one typed in English runs only after the operator answers y (--yes: on
    sim2sim only, which _apply_cli has checked). Places must be in the launch file's input.places."""
    from g1_control.program import ProgramError

    program = options.program
    if launch.input.pose != "estimator":
        raise LaunchFileError("input.pose: a robot steers a program by its own estimate; set input.pose: estimator")
    try:
        program.validate(launch.program_world())
    except ProgramError as exc:
        raise LaunchFileError(f"program: {exc}") from None
    origin = f'from "{options.program_text}"' if options.program_text else "from the program file"
    say(f"behaviour program ({origin}), run once control starts:\n{program.describe()}")
    if not options.program_text or options.yes:
        return True
    answer = ask("run this program on the robot? type y and Enter (anything else: no): ")
    if answer.strip().lower() in ("y", "yes"):
        return True
    say("not confirmed: nothing was sent to the robot")
    return False


def deploy(path: Path, options: DeployOptions, say: Callable[[str], None] = _say,
           ask: Callable[[str], str] = input, report: DeployReport | None = None) -> DeployReport:
    """Run one deploy session; raise PreflightRefused (after printing the table) when refused.
    `ask`: the operator's answer to a question (confirming a program typed in English).
    `report`: filled as the deploy goes (so a caller holds what was done even when it raises)."""
    report = report if report is not None else DeployReport(launch=str(path))
    pf = Preflight(frozenset(options.overrides))
    launch = pf.check_launch_file(path)
    if launch is not None:
        try:
            _apply_cli(launch, options)
        except LaunchFileError as exc:
            pf.record("launch_file", FAIL, f"command-line override: {exc}", overridable=False)
            launch = None
    if launch is None:
        pf.not_run([n for n in CHECKS if n != "launch_file" and n not in OPTIONAL_CHECKS], "no valid launch file")
        return _refuse(pf, report, say)
    if options.program is not None and not _confirm_program(launch, options, say, ask):
        report.refused = True
        report.end_reason = "program not confirmed by the operator"
        return report

    spec, policy_variant = pf.check_policy(launch)
    backend = device = hands = None
    normal, scheduling = realtime(launch.deploy.realtime_priority)
    say(f"scheduling: {scheduling}")
    try:
        if pf.check_interface(launch):
            from g1_control.deploy.backends import command_ttl_s, open_robot_backend

            try:
                backend = open_robot_backend(launch.backend, damping_kd=launch.safety.damping_kd,
                                             command_ttl_s=command_ttl_s(launch))
            except G1ControlError as exc:
                pf.record("interface", FAIL, str(exc), overridable=False)
        if backend is not None:
            say(f"listening to the robot on {backend.link.describe()} ...")
            pf.check_robot(backend, launch, policy_variant)
            if pf.results["state_stream"].status == "pass":
                pf.check_motion_service(backend, launch)
            else:
                pf.not_run(["motion_service"], "no robot state")
        else:
            pf.not_run(ROBOT_CHECKS, "no link to the robot")
        hands = _check_hands(pf, launch, backend is not None)
        device, open_error = _open_input(launch, backend, spec)
        if launch.input.type == "unitree_remote" and pf.results["variant"].status == "not run":
            pf.not_run(["estop_input"], "the remote's bytes ride in the robot's LowState_, and none arrived")
        else:
            pf.check_input(device, launch, open_error)
        if device is not None and options.program is not None:
            from g1_control.program.device import ProgramInput, describe_record

            # motion from the program, buttons and loss from the operator's device
            device = ProgramInput(options.program, launch.program_world(), pose="estimator",
                                  start_delay_s=launch.input.start_delay_s, operator=device,
                                  on_record=lambda r: say("program step " + describe_record(r)))
        if spec is not None or (launch.tracker.type == "wbc" and pf.results["policy"].status == "pass"):
            say(f"simulated dry run ({launch.deploy.dry_run_s:.0f} s lockstep MuJoCo"
                + (", the whole program" if options.program is not None or launch.input.type == "program" else "")
                + ") ...")
            normal.restore()  # as fast as it can, but never ahead of the host's other work
            try:
                pf.check_dry_run(launch, options.program)
            finally:
                realtime(launch.deploy.realtime_priority)
        else:
            pf.not_run(["dry_run"], "no valid policy")
        report.preflight = pf.as_dict()
        report.overridden = [r.name for r in pf.results.values() if r.overridden]
        if not pf.passed:
            return _refuse(pf, report, say)
        say("\npreflight\n" + pf.table())
        for name in report.overridden:
            say(f"!!! WARNING: preflight check '{name}' FAILED and was OVERRIDDEN (--override {name}): "
                f"{pf.results[name].reason}")
        if options.preflight_only:
            say("preflight passed (--preflight-only): nothing was sent to the robot")
            return report
        # a link that did not open and a device that did not open fail checks no override passes
        assert backend is not None and device is not None
        _control(launch, pf, backend, device, options, report, say)
        return report
    finally:
        if device is not None:
            device.close()
        if hands is not None:
            hands.close()
        if backend is not None:
            backend.close()
        normal.restore()


def _check_hands(pf: Preflight, launch: LaunchFile, robot_link_open: bool):
    """The preflight's hand rows (g1_control/deploy/hands.py); the open hand link, or None."""
    from g1_control.deploy.hands import HAND_CHECKS, check_hands, open_hand_link

    if launch.backend.hands != "dex3":
        check_hands(pf, launch, None)
        return None
    if not robot_link_open:
        pf.not_run(list(HAND_CHECKS), "no link to the robot")
        return None
    try:
        hands = open_hand_link(launch)
    except G1ControlError as exc:
        check_hands(pf, launch, None, str(exc))
        return None
    check_hands(pf, launch, hands)
    return hands


def _refuse(pf: Preflight, report: DeployReport, say) -> DeployReport:
    report.refused = True
    report.preflight = pf.as_dict()
    say("\npreflight\n" + pf.table())
    refusal = pf.refusal()
    refusal.report = report  # for --json
    raise refusal


def _control(launch: LaunchFile, pf: Preflight, backend: LinkBackend, device: InputDevice, options: DeployOptions,
             report: DeployReport, say) -> None:
    """The robot under the loop, from zero torque to damping, in the steps of _RobotControl."""
    control = _RobotControl(launch, backend, device, options, report, say)
    control.build_loop()
    control.check_chain(pf)
    control.open_run_folder()
    error = control.run()
    control.finish(error)


class _RobotControl:
    """One deploy's control phase: the loop built around the deploy state machine, checked against
    the dry run, logged into a run folder, run until the state machine has damped long enough, and
    reported. Each method is one step of _control, in order."""

    def __init__(self, launch: LaunchFile, backend: LinkBackend, device: InputDevice, options: DeployOptions,
                 report: DeployReport, say) -> None:
        self.launch, self.backend, self.device = launch, backend, device
        self.options, self.report, self.say = options, report, say
        self.buttons = OperatorButtons(device)
        self.t_start = time.monotonic()
        self.folder: RunFolder | None = None
        self.control_s = options.duration_s if options.duration_s is not None else launch.duration_s
        self._wrapped: list[DeployTracker] = []
        self.t_loop0 = time.monotonic()

    # -- the deploy state machine ----------------------------------------------------------------
    def _on_transition(self, t: Transition) -> None:
        self.say(f"[{t.t_s - self.t_start:7.2f} s] {t}")
        if self.folder is not None:
            self.folder.event({"type": "transition", "t_s": t.t_s, "from": t.source.value, "to": t.target.value,
                               "reason": t.reason})
        if t.target == DeployState.HOLD and not self.options.yes:
            self.say(f"holding the default pose: press {_keys_for(self.device, 'run') or 'run'} to start the policy")

    def _state_machine(self, inner: Tracker, safety: SafetyFilter) -> DeployTracker:
        """build_loop's wrap_tracker: the DeployTracker around the launch file's tracker."""
        from g1_control.trackers.locomotion import LocomotionPolicyTracker

        # The pose and gains of the ramp: the walking policy's own when it has them, else the robot's defaults.
        spec = inner.spec if isinstance(inner, LocomotionPolicyTracker) else None
        pose = spec.default_q_rad if spec is not None else g1.DEFAULT_Q_RAD
        kp, kd = (spec.kp, spec.kd) if spec is not None else (g1.KP_DEFAULT, g1.KD_DEFAULT)
        tracker = DeployTracker(inner, pose, kp, kd, safety, time.monotonic, self.launch.deploy, buttons=self.buttons,
                                auto=self.options.yes, control_s=self.control_s, on_transition=self._on_transition)
        self._wrapped.append(tracker)
        return tracker

    # -- the steps -------------------------------------------------------------------------------
    def build_loop(self) -> None:
        """The launch file's loop on the robot link, the state machine around its tracker."""
        from g1_control.launch.builder import build_loop
        from g1_control.program.device import ProgramInput

        # The per-tick log streams into the run folder (attached later): the loop keeps one chunk only.
        self.loop = build_loop(self.launch, backend=self.backend, input_device=self.buttons,
                               wrap_tracker=self._state_machine, wallclock=True, log_capacity=1)
        self.tracker, self.safety = self._wrapped[0], self.loop.safety
        # The variant the preflight accepted: a state reporting another mode_machine trips, and is never echoed.
        if self.backend.expected_mode_machine is not None:
            self.safety.expect_mode_machine(self.backend.expected_mode_machine)
        # A scripted timeline starts when control starts; so does a behaviour program (its own clock:
        # the operator device keeps the loop's).
        self.buttons.timeline_clock = self.tracker.control_elapsed_s
        if isinstance(self.device, ProgramInput):
            self.device.program_clock = self.tracker.control_elapsed_s

    def check_chain(self, pf: Preflight) -> None:
        """The robot's loop must be the one the dry run checked (G1ControlError otherwise)."""
        from g1_control.launch.builder import CHAIN_STAGES

        chain = self.loop.chain
        self.report.chain = dict(chain)
        dry = pf.dry_run.chain if pf.dry_run is not None else {}
        self.report.dry_run_chain = dict(dry)
        differs = [k for k in CHAIN_STAGES if dry.get(k) != chain.get(k)]
        if dry and differs:
            raise G1ControlError("the robot's loop differs from the one the dry run checked: " + "; ".join(
                f"{k}: dry run {dry.get(k)!r}, robot {chain.get(k)!r}" for k in differs))

    def open_run_folder(self) -> None:
        folder = self.folder = RunFolder.create(Path(self.options.out_root or self.launch.output.dir), self.launch)
        folder.attach(self.loop)
        self.report.run_dir = str(folder.run_dir)
        self.say(f"run folder: {folder.run_dir} (log, events and summary written as the deploy goes)")
        self.say("control chain (as checked by the dry run): " + " -> ".join(
            self.loop.chain[k] for k in ("generator", "retargeter", "tracker")))

    def run(self) -> G1ControlError | None:
        """Zero torque, then the loop until the state machine has damped for exit_damping_s; every way
        out (operator, signal, error) ends in damping. Returns the error that ended it, if one did."""
        previous = {sig: signal.signal(sig, self._on_signal) for sig in (signal.SIGINT, signal.SIGTERM)}
        error: G1ControlError | None = None
        self.t_loop0 = time.monotonic()
        try:
            self._start()
            self._loop()
        except KeyboardInterrupt:
            pass
        except G1ControlError as exc:
            error = exc
            self.safety.estop(f"error: {exc}", time.monotonic())
        finally:
            self._end_in_damping()
            for sig, handler in previous.items():
                signal.signal(sig, handler)
        return error

    def _on_signal(self, signum, frame) -> None:
        self.safety.estop(f"{signal.Signals(signum).name} received", time.monotonic(), planned=True)
        self.backend.damp()  # damping on the wire now, not at the next tick
        raise KeyboardInterrupt

    def _start(self) -> None:
        """Release the motion service (if asked), reset the loop: the robot is limp; say what starts it."""
        backend, device, launch = self.backend, self.device, self.launch
        if backend.release_motion_service:
            self.say("releasing the robot's built-in motion service ...")
        self.loop.reset()
        self.report.released_modes = list(backend.released_modes)
        self.say(f"zero torque: the robot is limp. Press {_keys_for(device, 'start') or 'start'} to ramp to the "
                 f"default pose over {launch.deploy.ramp_s:.1f} s"
                 + (f"; e-stop: {_keys_for(device, 'estop')}" if _keys_for(device, "estop") else "")
                 + (f"; stop (damping): {_keys_for(device, 'stop')}" if _keys_for(device, "stop") else "")
                 + (" (--yes: answered automatically)" if self.options.yes else ""))

    def _loop(self) -> None:
        tracker, exit_s = self.tracker, self.launch.deploy.exit_damping_s

        def finished() -> bool:
            now = time.monotonic()
            return tracker.observe_safety(now) and tracker.time_in_state_s(now) >= exit_s

        self.t_loop0 = time.monotonic()
        with frozen_heap():  # no full garbage collection of the whole heap inside the loop
            self.loop.scheduler.run(1 << 40, stop=finished)

    def _end_in_damping(self) -> None:
        self.backend.damp()
        tracker = self.tracker
        if tracker.state != DeployState.DAMPING:
            trip = self.safety.trip_event
            tracker._go(DeployState.DAMPING, f"{trip.kind.value}: {trip.detail}" if trip else "exit", time.monotonic())
            time.sleep(self.launch.deploy.exit_damping_s)  # damping keeps streaming before the link closes

    def finish(self, error: G1ControlError | None) -> None:
        """The log, the report and the run folder's summary; then the error that ended the run, if any."""
        folder, report = self.folder, self.report
        assert folder is not None  # open_run_folder ran
        self.loop.generator.close()  # a goal planner's process: no plan is made past the control phase
        log = folder.close_log(self.loop)
        _fill_report(report, log, self.loop, self.tracker, self.backend, self.safety, self.t_loop0, self.device)
        _report_goals(report, self.loop, self.launch, folder)
        _report_localisation(report, self.loop)
        folder.write_npz(log)
        status = ("error" if error is not None else "fault" if report.fault
                  else "interrupted" if report.end_reason.startswith("SIG") else "completed")
        folder.finish(status, report.end_reason, dataclasses.asdict(report))
        _print_summary(report, self.say)
        if error is not None:
            raise error


def _fill_report(report: DeployReport, log_arrays: dict, loop, tracker: DeployTracker, backend, safety,
                 t_loop0: float, program: InputDevice) -> None:
    """`program`: the operator's device inside OperatorButtons (a ProgramInput when a behaviour
    program drove the robot: its step records go into the report)."""
    from g1_control.report.results import upper_body_rms_by_style

    report.sequence = tracker.sequence
    report.transitions = [{"t_s": t.t_s, "from": t.source.value, "to": t.target.value, "reason": t.reason}
                          for t in tracker.transitions]
    trip = safety.trip_event
    report.end_reason = trip.detail if trip else "exit"
    # A planned ending (operator stop, control time over, a signal) exits 0; any other trip is a fault (exit 3).
    report.fault = trip is None or not trip.planned
    report.safety_events = [{"t_s": e.t_s, "kind": e.kind.value, "detail": e.detail, "trips": e.trips,
                             "planned": e.planned} for e in safety.events]
    report.link = dataclasses.asdict(backend.stats())
    control = [t for t in tracker.transitions if t.target == DeployState.CONTROL]
    if control:
        start = control[0].t_s
        end = next((t.t_s for t in tracker.transitions if t.source == DeployState.CONTROL), time.monotonic())
        t_mono = t_loop0 + log_arrays["t_s"]
        # Skip the first 2 s (the gait starting up) when there is enough control time for it.
        steady_from = start + (2.0 if end - start > 4.0 else 0.0)
        window = (t_mono >= steady_from) & (t_mono < end)
        est = log_arrays["velocity_est"][window]
        cmd = log_arrays["command"][window]
        report.control = {"duration_s": end - start, "steady_window_s": max(0.0, end - steady_from),
                          "velocity_est_mean": est.mean(axis=0).tolist() if len(est) else None,
                          "command_mean": cmd.mean(axis=0).tolist() if len(cmd) else None,
                          "upper_body_vs_plan": upper_body_rms_by_style(log_arrays, (t_mono >= start) & (t_mono < end))}
    from g1_control.program.device import ProgramInput, record_dict

    if isinstance(program, ProgramInput):
        report.control["program"] = {"steps": [record_dict(r) for r in program.records],
                                     "finished": program.done and not program.runner.stopped}
    late, stages = loop.scheduler.lateness.summary(), loop.scheduler.report()
    report.loop = {"deadline_misses": loop.scheduler.deadline_misses, "ticks": loop.scheduler.tick_index,
                   "tick_p99_us": stages["tick"]["p99_us"], "stages_us": stages,
                   "lateness_p99_ms": late["p99_us"] / 1000, "lateness_max_ms": loop.scheduler.max_lateness_s * 1000,
                   "misses_over_period": loop.scheduler.misses_over_period,
                   "skipped_ticks": loop.scheduler.skipped_ticks,
                   "clamped_commands": safety.clamps.commands}
    if loop.generator.plan_windows:
        report.loop["while_planning"] = lateness_while(log_arrays, t_loop0, loop.generator.plan_windows,
                                                       1.0 / loop.rates.tracker_hz, safety.config.overrun_lateness_s)


def lateness_while(log: dict, t_loop0: float, windows, row_period_s: float, allowance_s: float) -> dict:
    """How late the loop's ticks were while plans were made beside it: the log's rows (late_s) within the
    plans' windows (Generator.plan_windows, in the states' monotonic time) and one row after each. Windows
    are listed from the loop's start (the log's t_s)."""
    t_mono = t_loop0 + log["t_s"]
    rows = np.zeros(len(t_mono), dtype=bool)
    for _, start, end in windows:
        rows |= (t_mono >= start) & (t_mono <= end + row_period_s)
    late = log["late_s"][rows]
    return {"plans": len(windows), "seconds": float(sum(end - start for _, start, end in windows)),
            "rows": int(rows.sum()), "lateness_p99_ms": float(np.percentile(late, 99) * 1000) if late.size else 0.0,
            "lateness_max_ms": float(late.max() * 1000) if late.size else 0.0,
            "rows_late": int((late > allowance_s).sum()), "allowance_ms": allowance_s * 1000,
            "windows": [{"what": what, "start_s": start - t_loop0, "seconds": end - start} for what, start, end in windows]}


def _report_goals(report: DeployReport, loop, launch: LaunchFile, folder: RunFolder) -> None:
    """Every goal's status and message (the execution layer's verdicts) into the report and the run
    folder's events, with the execution layer's notes (goal started, failed and why, ...) as they came."""
    from g1_control.launch.builder import timeline_of
    from g1_control.report.outcomes import goal_reports
    from g1_control.teleop.scripted import timeline_goals

    if not launch.executes_goals:
        return
    for t_s, text in loop.generator.goal_log:
        folder.event({"type": "goal_note", "t_s": t_s, "text": text})
    report.goals = goal_reports(loop.generator, timeline_goals(timeline_of(launch)))
    for goal in report.goals:
        folder.event({"type": "goal", **goal})


def _report_localisation(report: DeployReport, loop) -> None:
    """The localiser's last pose, its pose when damping began (the robot then stops walking: judged against
    a simulator's ground truth there) and external pose counters into the report; its pose topic is closed."""
    localiser = loop.localiser
    if localiser is None:
        return
    pose = localiser.pose
    out: dict = {"source": localiser.describe().split(";")[0],
                 "pose": None if pose is None else {"x_m": pose.x_m, "y_m": pose.y_m, "z_m": pose.z_m,
                                                    "yaw_rad": pose.yaw_rad}}
    damping = next((t["t_s"] for t in report.transitions if t["to"] == "damping"), None)
    at = localiser.pose_at(damping) if damping is not None else None
    out["pose_at_damping"] = None if at is None else {"t_s": at.t_s, "x_m": at.x_m, "y_m": at.y_m, "yaw_rad": at.yaw_rad}
    if localiser.fusion is not None:
        c = localiser.fusion.counters
        out["external_pose"] = {"accepted": c.accepted, "rejected": dict(c.rejected), "last_rejection": c.last_rejection,
                                "max_correction_m": c.max_correction_m, "reacquired": c.reacquired,
                                "max_reacquire_m": c.max_reacquire_m}
    if localiser.objects is not None:
        p = localiser.objects.counters
        out["perception"] = {"frames": p.frames, "platform_frames": p.platform_frames, "rejected": dict(p.rejected),
                             "last_rejection": p.last_rejection,
                             "objects_w_m": {n: [float(v) for v in xyz] for n, xyz in localiser.objects.positions.items()},
                             "platforms_w_m": {n: {"center_xy_m": [float(v) for v in b.center_xy_m],
                                                   "size_xy_m": [float(v) for v in b.size_xy_m],
                                                   "height_m": float(b.height_m), "yaw_rad": float(b.yaw_rad)}
                                               for n, b in localiser.objects.platforms.items()}}
    report.localisation = out
    localiser.close()


def _print_summary(report: DeployReport, say) -> None:
    link = report.link
    say(f"deploy ended in damping: {report.end_reason}" + (" (FAULT)" if report.fault else ""))
    if report.run_dir:
        say(f"run folder: {report.run_dir}")
    say(f"states: {' -> '.join(report.sequence)}")
    say(f"lowcmd sent {link['commands_sent']} ({link['command_rate_hz']:.0f} Hz, p99 period "
        f"{link['command_period_p99_s'] * 1000:.2f} ms at the sender); lowstate received {link['states_received']}, "
        f"{link['bad_crc']} bad CRC, {link['malformed']} malformed")
    if link.get("holds"):
        say(f"lowcmd hold form: {link['holds']} time(s) the loop stalled past the command's "
            f"{link['command_ttl_s'] * 1000:.0f} ms life; {link['commands_held']} messages held the pose without "
            "feedforward torque or velocity targets")
    v = report.control.get("velocity_est_mean") if report.control else None
    if v is not None:
        c = report.control["command_mean"]
        say(f"control {report.control['duration_s']:.1f} s: estimated velocity vx {v[0]:+.2f} m/s, vy {v[1]:+.2f}, "
            f"wz {v[2]:+.2f} (commanded {c[0]:+.2f}, {c[1]:+.2f}, {c[2]:+.2f})")
    for style, fig in (report.control.get("upper_body_vs_plan") or {}).items():
        say(f"upper body vs plan, style {style}: RMS {fig['rms_rad']:.3f} rad over {fig['seconds']:.1f} s")
    if report.goals:
        from g1_control.report.outcomes import outcome_line

        say("goals (the execution layer's own verdicts; a robot has no ground truth):")
        for goal in report.goals:
            say("  " + outcome_line(goal))
    loc = report.localisation
    if loc:
        pose = loc["pose"]
        where = "no pose" if pose is None else (f"last pose ({pose['x_m']:+.2f}, {pose['y_m']:+.2f}) m, heading "
                                                f"{math.degrees(pose['yaw_rad']):+.0f} deg in the scene")
        line = f"localisation ({loc['source']}, anchored at the start): {where}"
        ext = loc.get("external_pose")
        if ext is not None:
            refused = ", ".join(f"{n} {why}" for why, n in ext["rejected"].items() if n) or "none"
            line += f"; external poses: {ext['accepted']} accepted, refused: {refused}"
            if ext["last_rejection"]:
                line += f" (last: {ext['last_rejection']})"
        seen = loc.get("perception")
        if seen is not None:
            refused = ", ".join(f"{n} {why}" for why, n in seen["rejected"].items() if n) or "none"
            platforms = "".join(f"; platform {n} seen at ({p['center_xy_m'][0]:+.2f}, {p['center_xy_m'][1]:+.2f}) m, "
                                f"{p['height_m']:.2f} m high" for n, p in seen["platforms_w_m"].items())
            line += (f"; perception: {seen['frames']} object frames, {seen['platform_frames']} platform frames, "
                     f"refused: {refused}{platforms}")
        say(line)
    say(f"loop: {report.loop['ticks']} ticks, {report.loop['deadline_misses']} deadline misses (worst "
        f"{report.loop['lateness_max_ms']:.1f} ms late, p99 {report.loop['lateness_p99_ms']:.1f} ms; "
        f"{report.loop['skipped_ticks']} ticks skipped after stalls), "
        f"{report.loop['clamped_commands']} commands clamped by the safety layer")
    planning = report.loop.get("while_planning")
    if planning:
        say(f"loop while goals were planned ({planning['plans']} plans, {planning['seconds']:.1f} s): "
            f"{planning['rows']} logged ticks, worst {planning['lateness_max_ms']:.1f} ms late, p99 "
            f"{planning['lateness_p99_ms']:.1f} ms, {planning['rows_late']} late by more than "
            f"{planning['allowance_ms']:.0f} ms")


def write_report(report: DeployReport, path: Path) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(report.to_json())

