"""The preflight checklist of `g1 deploy`: every check runs (so the operator sees everything that
is wrong at once), the table prints, and any failure refuses to start.

A failed check can be overridden with `--override NAME`; the override is printed in the table,
logged at ERROR level and recorded in the deploy report. Some failures cannot be overridden,
because nothing can run safely past them: an invalid launch file or policy, a missing interface,
no robot state at all, a robot of another DoF variant, an operator input that cannot be opened
or is lost.
"""

from __future__ import annotations

import dataclasses
import logging
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from g1_control.errors import G1ControlError, MotionServiceError, RobotNotConnectedError, VariantMismatchError
from g1_control.launch.schema import EstimationConfig, InputConfig, LaunchFile, Segment
from g1_control.loop.control_loop import first_fault
from g1_control.robot import g1
from g1_control.rotations import tilt_rad

if TYPE_CHECKING:
    from g1_control.report.results import RunResult

log = logging.getLogger("g1_control.deploy")

CHECKS: dict[str, str] = {
    "launch_file": "the launch file parses and validates",
    "policy": "policy metadata fits the G1 (joint order, gains, default pose) and its ONNX file",
    "interface": "the robot link's network interface (or port) exists and is up",
    "variant": "the robot's mode_machine is the DoF variant the launch file and policy are for",
    "state_stream": "LowState arrives at >= deploy.min_state_rate_hz with valid CRCs, every value finite",
    "peers": "exactly one publisher of the robot's state (rt/lowstate) and no other writer of its commands",
    "motion_service": "the built-in controller will let go: released by g1 deploy (backend.release_motion_service) "
                      "or none active (debug mode); asked with CheckMode only",
    "imu_upright": "the pelvis leans less than deploy.max_start_tilt_rad",
    "joint_limits": "every joint reads inside its limits",
    "temperatures": "every motor is cooler than deploy.max_start_temperature_c",
    "battery": "battery voltage above deploy.min_battery_v (when the robot reports it)",
    "hands_present": "both Dex3-1 hands publish HandState_ (backend.hands: dex3; g1_control/deploy/hands.py)",
    "hand_state_stream": "each hand's HandState_ arrives at >= 50 Hz and is not frozen",
    "finger_limits": "every finger joint reads inside its URDF limits",
    "estop_input": "the operator input opens, has an e-stop, and is not lost",
    "dry_run": "a lockstep MuJoCo run of the same launch file does not fall",
}
"""Check name -> what it asserts (the names --override takes)."""
OPTIONAL_CHECKS = frozenset({"hands_present", "hand_state_stream", "finger_limits"})
"""Rows in the table only where they apply (the hand rows: backend.hands dex3, deploy/hands.py)."""

PASS, FAIL, SKIP, NOT_RUN = "pass", "fail", "skip", "not run"
MOTION_SERVICE_WAIT_S = 1.0
"""How long the motion_service check waits for the service's CheckMode answer."""
DEBUG_MODE = ("put the robot in debug mode with its remote: with the robot hanging in zero-torque mode press "
              "L2+R2 (then L2+A to damp), or let g1 deploy release the service (backend.release_motion_service: "
              "true)")
"""The step people miss (Unitree's deploy guides; unitree_rl_gym's deploy_real README)."""


def nonfinite_fields(state) -> list[str]:
    """RobotState fields (with the joint or index) that hold NaN or inf."""
    from g1_control.safety.filter import STATE_FIELDS

    out = []
    for name in STATE_FIELDS:
        arr = np.asarray(getattr(state, name), dtype=float)
        for i in np.nonzero(~np.isfinite(arr))[0]:
            out.append(f"{name}[{g1.JOINT_NAMES[i] if arr.shape == (g1.NUM_JOINTS,) else i}] = {arr[i]}")
    return out


class PreflightRefused(G1ControlError):
    """A preflight check failed and was not overridden: nothing was sent to the robot."""

    report: Any = None
    """The refused deploy's DeployReport (g1_control.deploy.session sets it, for --json)."""


@dataclass
class CheckResult:
    name: str
    status: str
    reason: str
    overridable: bool = True
    overridden: bool = False

    @property
    def blocks(self) -> bool:
        return self.status in (FAIL, NOT_RUN) and not self.overridden


@dataclass
class Preflight:
    overrides: frozenset[str] = frozenset()
    results: dict[str, CheckResult] = field(default_factory=dict)
    dry_run: RunResult | None = None
    """The dry run's result, when it ran."""

    def __post_init__(self) -> None:
        unknown = set(self.overrides) - set(CHECKS)
        if unknown:
            raise G1ControlError(f"--override {', '.join(sorted(unknown))}: no such check; checks: {', '.join(CHECKS)}")
        for name in CHECKS:
            if name not in OPTIONAL_CHECKS:
                self.results[name] = CheckResult(name, NOT_RUN, "not run")

    def record(self, name: str, status: str, reason: str, *, overridable: bool = True) -> bool:
        result = CheckResult(name, status, reason, overridable)
        if status == FAIL and name in self.overrides:
            if overridable:
                result.overridden = True
                log.error("PREFLIGHT OVERRIDE: check '%s' failed (%s) and is overridden by --override %s",
                          name, reason, name)
            else:
                result.reason += f" (--override {name} refused: this failure cannot be overridden)"
        self._put(result)
        return status != FAIL

    def _put(self, result: CheckResult) -> None:
        """Store `result`; an optional row new to the table takes its place in CHECKS order (rows of
        other names, such as g1 doctor's, keep theirs)."""
        new = result.name not in self.results
        self.results[result.name] = result
        if new and result.name in OPTIONAL_CHECKS:
            order = [n for n in CHECKS if n in self.results] + [n for n in self.results if n not in CHECKS]
            self.results = {n: self.results[n] for n in order}

    def not_run(self, names, why: str) -> None:
        for name in names:
            if name not in self.results or self.results[name].status == NOT_RUN:
                self._put(CheckResult(name, NOT_RUN, f"not run: {why}"))

    # -- the checks ----------------------------------------------------------------------------------
    def check_launch_file(self, path: Path) -> LaunchFile | None:
        from g1_control.launch.schema import load_launch

        try:
            launch = load_launch(path)
        except G1ControlError as exc:
            self.record("launch_file", FAIL, str(exc), overridable=False)
            return None
        if launch.backend.type == "mujoco":
            self.record("launch_file", FAIL, f"{path}: backend.type is mujoco; g1 deploy drives a robot link "
                        "(unitree_dds, can, serial). Simulate with `g1 launch`", overridable=False)
            return None
        self.record("launch_file", PASS, f"{path}: {launch.name} ({launch.backend.type}, input {launch.input.type})"
                    + _goals_without_world_pose(launch))
        return launch

    def check_policy(self, launch: LaunchFile):
        from g1_control.trackers.policy_spec import load_spec, read_spec_file, resolve_spec_path

        if launch.tracker.type == "wbc":
            return self.check_model_based(launch)
        try:
            spec = load_spec(launch.tracker.policy)
            variant = read_spec_file(resolve_spec_path(launch.tracker.policy)).variant
        except G1ControlError as exc:
            self.record("policy", FAIL, str(exc), overridable=False)
            return None, None
        if variant is not None and variant != launch.backend.expected_variant:
            self.record("policy", FAIL, f"policy '{spec.name}' is for the {variant} G1 but backend.expected_variant "
                        f"is {launch.backend.expected_variant}; use a policy made for this robot", overridable=False)
            return None, variant
        over = [(name, float(np.max(gains)), cap) for name, gains, cap in
                (("kp", spec.kp, launch.safety.max_kp), ("kd", spec.kd, launch.safety.max_kd)) if np.max(gains) > cap]
        if over:
            name, gain, cap = over[0]
            self.record("policy", FAIL, f"policy '{spec.name}' uses {name} up to {gain:g} but safety.max_{name} is "
                        f"{cap:g}: every command would be clamped; raise the cap or lower the policy's gains",
                        overridable=False)
            return None, variant
        self.record("policy", PASS, f"{spec.name}: {len(spec.joint_names)} joints in G1 order, gains and default pose "
                    f"match the robot, ONNX {spec.onnx_path.name}" + (f", for {variant}" if variant else ""))
        return spec, variant

    def check_model_based(self, launch: LaunchFile):
        """tracker.type wbc: no learned policy; the model-based controller runs the launch file's
        variant from that variant's own model, so any G1 variant passes. (None, the variant's name)."""
        from g1_control.launch.variant import robot_variant

        variant = robot_variant(launch)
        self.record("policy", PASS, f"tracker.type wbc: no learned policy; the model-based controller runs the "
                    f"{variant.name} model ({variant.num_dof} joints)")
        return None, variant.name

    def check_interface(self, launch: LaunchFile) -> bool:
        from g1_control.deploy.backends import check_link_endpoint

        try:
            what = check_link_endpoint(launch.backend)
        except G1ControlError as exc:
            return self.record("interface", FAIL, str(exc), overridable=False)
        return self.record("interface", PASS, what)

    def check_robot(self, backend, launch: LaunchFile, policy_variant: str | None):
        """variant, state_stream, imu_upright, joint_limits, temperatures, battery; the state or None."""
        from g1_control.hardware.unitree.conversions import variant_of

        cfg = launch.deploy
        try:
            state = backend.wait_for_state(launch.backend.connect_timeout_s)
        except RobotNotConnectedError as exc:
            self.record("state_stream", FAIL, str(exc) + _simulator_hint(backend, launch), overridable=False)
            self.not_run(("variant", "peers", "imu_upright", "joint_limits", "temperatures", "battery"),
                         "no robot state")
            return None
        # Rate and CRC health over a window, from the transport's own counters.
        tick0 = backend.read_state().tick
        before, t0 = backend.stats(), time.monotonic()
        time.sleep(cfg.state_window_s)
        after, elapsed = backend.stats(), time.monotonic() - t0
        min_rate = _min_state_rate_hz(backend, launch)
        rate = (after.states_received - before.states_received) / elapsed
        bad, malformed = after.bad_crc - before.bad_crc, after.malformed - before.malformed
        bad_frames = after.bad_frames - before.bad_frames
        where = backend.link.describe()
        detail = (f"{rate:.0f} Hz over {elapsed:.1f} s, {bad} bad CRC, {malformed} malformed"
                  + (f", {bad_frames} bad frames" if bad_frames else ""))
        frozen = _tick_frozen(backend, tick0, after.states_received - before.states_received, elapsed)
        if rate < min_rate:
            self.record("state_stream", FAIL, f"{detail}; need >= {min_rate:.0f} Hz on {where}: check the "
                        "cable/switch and that nothing else loads this host")
        elif frozen:
            # Not overridable: the loop's tick-order check would damp on the first tick anyway.
            self.record("state_stream", FAIL, f"{detail}; {frozen}{_simulator_hint(backend, launch)}",
                        overridable=False)
        elif bad or malformed or bad_frames:
            self.record("state_stream", FAIL, f"{detail}; corrupted samples on {where}: check the cable, the switch "
                        "and that only one robot publishes on this domain")
        else:
            state = backend.read_state()
            invalid = nonfinite_fields(state)
            if invalid:
                self.record("state_stream", FAIL, f"{detail}; the robot reports values that are not finite numbers: "
                            f"{', '.join(invalid[:4])}{' ...' if len(invalid) > 4 else ''}: a sensor or its decoding "
                            "is broken", overridable=False)
            else:
                self.record("state_stream", PASS, detail + _simulator_filled(backend, launch))
        state = backend.read_state()
        self.check_peers(backend)

        try:
            variant = variant_of(state.mode_machine)
        except VariantMismatchError as exc:
            self.record("variant", FAIL, str(exc) + _simulator_hint(backend, launch), overridable=False)
            variant = None
        if variant is not None:
            if variant.name != launch.backend.expected_variant:
                self.record("variant", FAIL, f"the robot reports mode_machine {state.mode_machine} ({variant.name}, "
                            f"{variant.num_dof} DoF) but the launch file expects {launch.backend.expected_variant}"
                            + (f" and the policy is for {policy_variant}" if policy_variant else "")
                            + "; use a launch file and policy made for this robot", overridable=False)
            else:
                self.record("variant", PASS, f"mode_machine {state.mode_machine} ({variant.name}, {variant.num_dof} DoF)"
                            + _mode_machine_filled(backend))
        active = variant.active_mask if variant is not None else np.ones(g1.NUM_JOINTS, dtype=bool)

        tilt = tilt_rad(state.imu_quat_wxyz) if np.all(np.isfinite(state.imu_quat_wxyz)) else float("nan")
        if np.isfinite(tilt) and tilt <= cfg.max_start_tilt_rad:
            self.record("imu_upright", PASS, f"tilt {tilt:.3f} rad (limit {cfg.max_start_tilt_rad:.2f})")
        else:
            self.record("imu_upright", FAIL, f"tilt {tilt:.3f} rad > {cfg.max_start_tilt_rad:.2f}: stand the robot up "
                        "or hang it on its gantry before starting")

        tol = cfg.joint_limit_tolerance_rad
        q = state.q_rad
        nonfinite = [j for j in np.nonzero(active & ~np.isfinite(q))[0]]
        out = [j for j in np.nonzero(active & ((q < g1.Q_MIN_RAD - tol) | (q > g1.Q_MAX_RAD + tol)))[0]]
        if nonfinite:
            listed = ", ".join(f"{g1.JOINT_NAMES[j]} reads {q[j]}" for j in nonfinite[:3])
            self.record("joint_limits", FAIL, f"{len(nonfinite)} joints read no number: {listed}"
                        + (" ..." if len(nonfinite) > 3 else "") + "; the encoder or its decoding is broken: do not "
                        "start", overridable=False)
        elif out:
            listed = ", ".join(f"{g1.JOINT_NAMES[j]} {q[j]:+.3f} rad [{g1.Q_MIN_RAD[j]:+.3f}, {g1.Q_MAX_RAD[j]:+.3f}]"
                               for j in out[:3])
            self.record("joint_limits", FAIL, f"{len(out)} joints outside their limits: {listed}"
                        + (" ..." if len(out) > 3 else "") + "; move them back by hand with the motors off")
        else:
            self.record("joint_limits", PASS, f"{int(active.sum())} joints inside their limits (±{tol:.2f} rad)")

        temps = np.where(active, state.motor_temperature_c, -np.inf)
        bad = np.nonzero(active & ~np.isfinite(state.motor_temperature_c))[0]
        j = int(bad[0]) if bad.size else int(np.argmax(temps))
        if bad.size or not temps[j] < cfg.max_start_temperature_c:
            self.record("temperatures", FAIL, f"{g1.JOINT_NAMES[j]} motor at {temps[j]:.0f} °C (limit "
                        f"{cfg.max_start_temperature_c:.0f} °C): let the motors cool down")
        else:
            self.record("temperatures", PASS, f"hottest {g1.JOINT_NAMES[j]} at {temps[j]:.0f} °C "
                        f"(limit {cfg.max_start_temperature_c:.0f} °C)")

        battery = state.battery_v
        if battery is None:
            self.record("battery", SKIP, "not reported: the G1's LowState_ carries no battery voltage (its BMS "
                        "publishes on its own topic); check the charge on the robot's display")
        elif not battery >= cfg.min_battery_v:  # NaN fails too
            self.record("battery", FAIL, f"battery at {battery:.1f} V (limit {cfg.min_battery_v:.1f} V): charge it")
        else:
            self.record("battery", PASS, f"battery at {battery:.1f} V")
        return state

    def check_peers(self, backend) -> bool:
        """One publisher of the robot's state, no other writer of its commands (where the link can tell)."""
        if not backend.sees_peers:
            return self.record("peers", SKIP, "this backend cannot see its peers")
        backend.refresh_peers()
        senders, writers, command_writers = backend.peers()
        where = backend.link.describe()
        if writers is None and senders == 0:
            return self.record("peers", SKIP, f"{where} carries bytes, not writers: a second sender shows only as a "
                               "tick running backwards, which trips the run")
        n = max(writers or 0, senders)
        if n > 1:
            return self.record("peers", FAIL, f"{n} publishers on rt/lowstate ({senders} sent within the last second) "
                               f"on {where}: another robot or program publishes robot state on this domain and "
                               "partition; find and stop it (only one robot may talk to this host)", overridable=False)
        if command_writers:
            return self.record("peers", FAIL, f"{command_writers} other writer(s) of rt/lowcmd on {where}: another "
                               "program commands this robot; stop it first", overridable=False)
        return self.record("peers", PASS, f"one publisher on rt/lowstate, no other writer of rt/lowcmd ({where})")

    def check_motion_service(self, backend, launch: LaunchFile) -> bool:
        """Ask the robot's motion-switcher service which built-in controller runs (CheckMode only: nothing
        is released here) and whether g1 deploy's release will find it; shared with g1 doctor."""
        from g1_control.hardware.links.dds import DdsLink
        from g1_control.hardware.unitree.motion_service import MotionServiceClient

        b, name = launch.backend, "motion_service"
        if not isinstance(backend.link, DdsLink):
            return self.record(name, SKIP, f"{backend.link.describe()} has no motion service to ask")
        if b.simulator is not None:
            return self.record(name, SKIP, f"backend.simulator {b.simulator}: a simulator runs no motion service; "
                               "nothing is released")
        client = MotionServiceClient(backend.link.participant, b.partition, timeout_s=MOTION_SERVICE_WAIT_S)
        t0 = time.monotonic()
        try:
            mode = client.check_mode()
        except MotionServiceError as exc:
            silent = f"no motion service answered within {time.monotonic() - t0:.1f} s"
            if b.release_motion_service:
                return self.record(name, FAIL, f"{silent}, and backend.release_motion_service is true: the release "
                                   "would fail before control starts. If the robot is in debug mode already (L2+R2 on "
                                   "its remote), skip the release: --no-release-motion-service (or "
                                   f"backend.release_motion_service: false) ({exc})", overridable=False)
            return self.record(name, SKIP, f"{silent}: debug mode assumed (backend.release_motion_service false)")
        finally:
            client.close()  # its entities deleted now, under the process-wide DDS entity lock
        if not mode:
            return self.record(name, PASS, "no built-in controller active: ready for low-level control")
        if b.release_motion_service:
            return self.record(name, PASS, f"built-in controller '{mode}' active; g1 deploy will release it "
                               "(ReleaseMode) before it sends anything")
        return self.record(name, FAIL, f"built-in controller '{mode}' active and backend.release_motion_service "
                           f"is false: the robot would mix its own commands with ours. {DEBUG_MODE}",
                           overridable=False)

    def check_input(self, device, launch: LaunchFile, open_error: str | None = None) -> bool:
        """The operator's device: opened, bound to an e-stop, not lost while polled."""
        if open_error is not None:
            return self.record("estop_input", FAIL, open_error, overridable=False)
        kind = launch.input.type
        if kind in ("scripted", "random", "gamepad_script", "program", "ros2"):
            if launch.backend.type == "unitree_dds" and launch.backend.interface == "lo":
                return self.record("estop_input", PASS, f"{kind} input against the emulator on lo (sim2sim): no "
                                   "operator e-stop; Ctrl-C or SIGTERM damps")
            return self.record("estop_input", FAIL, f"input.type {kind} has no operator e-stop; a robot needs "
                               "unitree_remote, gamepad or keyboard")
        bound = device.button_chords("estop")
        deadline = time.monotonic() + launch.deploy.input_check_s
        while time.monotonic() < deadline and not device.lost:
            device.poll(time.monotonic())
            time.sleep(0.02)
        device.poll(time.monotonic())
        if device.lost:
            return self.record("estop_input", FAIL, f"{kind} lost: {device.lost_reason or '?'}; reconnect it "
                               "and start again", overridable=False)
        if not bound:
            return self.record("estop_input", FAIL, f"{kind} mapping binds no button to estop; bind one in "
                               "input.device.mapping.buttons")
        return self.record("estop_input", PASS, f"{kind} answering; e-stop on {', '.join(bound)}")

    def check_dry_run(self, launch: LaunchFile, program=None) -> bool:
        """A lockstep MuJoCo run of the launch file (with `program`: of that behaviour program) must not fall."""
        from g1_control.launch.runner import run as run_sim

        sim = dry_run_launch(launch, program)
        try:
            result = run_sim(sim, progress=False, end_with_program=False)
        except G1ControlError as exc:
            return self.record("dry_run", FAIL, f"the simulated dry run could not run: {exc}")
        self.dry_run = result
        moved = ", ".join(_segment_speed(s, result.duration_s) for s in result.segments if abs(s.commanded[0]) > 0)
        driver = (f"the model-based controller on the {launch.backend.expected_variant} G1"
                  if launch.tracker.type == "wbc" else f"policy {launch.tracker.policy}")
        what = (f"{result.duration_s:.1f} s lockstep MuJoCo of {driver} at the launch "
                f"file's rates ({result.wall_s:.1f} s wall)" + (f"; {moved}" if moved else ""))
        if result.fell:
            fall = result.fall or {}
            when = f" at {fall['t_s']:.1f} s ({fall['detail']})" if fall else ""
            return self.record("dry_run", FAIL, f"FELL in simulation{when}: "
                               f"{what}; do not run this policy/launch file on the robot")
        fault = first_fault(result.events)
        if fault is not None:
            return self.record("dry_run", FAIL, f"the safety layer tripped in simulation: {fault['kind']}: "
                               f"{fault['detail']}")
        ran = result.extra.get("program")
        if ran is not None:
            missed = [s["label"] for s in ran["steps"] if not s.get("verdict", {}).get("ok", True)]
            what += (f"; program {'finished' if ran['finished'] else 'STOPPED'}, {len(ran['steps'])} steps"
                     + (f", missed by ground truth: {', '.join(missed)}" if missed else ""))
            if not ran["finished"]:
                return self.record("dry_run", FAIL, f"the program did not finish in simulation: {what}")
        return self.record("dry_run", PASS, f"no fall: {what}")

    # -- verdict -----------------------------------------------------------------------------------------
    @property
    def passed(self) -> bool:
        return not any(r.blocks for r in self.results.values())

    def refusal(self) -> PreflightRefused:
        blocking = [r for r in self.results.values() if r.blocks]
        fixable = [r.name for r in blocking if r.overridable and r.status == FAIL]
        hint = (f"; fix them, or override a check you have verified yourself with --override NAME "
                f"(overridable here: {', '.join(fixable)})") if fixable else "; fix them first"
        return PreflightRefused(f"preflight failed ({', '.join(r.name for r in blocking)}): nothing was sent to "
                                f"the robot{hint}")

    def table(self) -> str:
        return format_table(list(self.results.values()))

    def as_dict(self) -> list[dict]:
        return [dataclasses.asdict(r) for r in self.results.values()]


def _goals_without_world_pose(launch: LaunchFile) -> str:
    """'; note: goal seg2.0 (...) is placed by the robot's own estimate ...' for the launch file's goals
    that need a world pose, which a robot does not report ('' when none does): they steer by the
    localiser (estimation/localiser.py), anchored where the run starts."""
    from g1_control.generator.goals.executor import world_pose_needed
    from g1_control.launch.builder import timeline_of
    from g1_control.teleop.scripted import timeline_goals

    placed = [g for g in timeline_goals(timeline_of(launch)) if world_pose_needed(g) is not None]
    if not placed:
        return ""
    source = "leg odometry" + (" fused with the external pose" if launch.estimation.external_pose else "")
    return "".join(f"; note: goal {g.goal_id} ({g.describe()}) is placed by the robot's own estimate ({source}, "
                   "anchored where it starts: the scene's origin, facing +x)" for g in placed)


def _segment_speed(segment, run_s: float) -> str:
    """'walk +0.42 m/s', or, for a segment the dry run did not reach (no samples: no speed), why not."""
    if np.isfinite(segment.achieved[0]):
        return f"{segment.label} {segment.achieved[0]:+.2f} m/s"
    return f"{segment.label} not reached (starts at {segment.start_s:.1f} s, the dry run ran {run_s:.1f} s)"


# -- Unitree's simulators (backend.simulator; g1_control/hardware/unitree/simulators.py) ------------------
def _min_state_rate_hz(backend, launch: LaunchFile) -> float:
    from g1_control.hardware.unitree.simulators import min_state_rate_hz

    unset = backend.unset_fields
    return min_state_rate_hz(unset.profile if unset is not None else None, launch.deploy.min_state_rate_hz)


def _tick_frozen(backend, tick0: int, received: int, elapsed_s: float) -> str:
    """Why the stream is frozen ('' when it is not): samples kept arriving over the window but their
    tick never advanced (a stuck publisher resending one sample; the loop would trip on it at once)."""
    tick = backend.read_state().tick
    if received < 2 or tick != tick0:
        return ""
    return (f"tick frozen: {received} samples arrived in {elapsed_s:.1f} s, every one with tick {tick}: the "
            "robot's state publisher is stuck (the control loop would trip on 'tick frozen' at once)")


def _simulator_hint(backend, launch: LaunchFile) -> str:
    """The hint that the stream looks like Unitree's simulator ('' when not, or when it is configured)."""
    from g1_control.hardware.links.network import LOOPBACK
    from g1_control.hardware.unitree.simulators import simulator_hint

    if launch.backend.simulator is not None:
        return ""
    loopback = launch.backend.type == "unitree_dds" and launch.backend.interface == LOOPBACK
    sample = backend.rejected_sample
    if sample is not None:
        return simulator_hint(sample, loopback=loopback)
    try:
        state = backend.read_state()
    except G1ControlError:
        return ""
    return simulator_hint(None, tick=state.tick, mode_machine=state.mode_machine, loopback=loopback)


def _simulator_filled(backend, launch: LaunchFile) -> str:
    """'; backend.simulator unitree_mujoco (200 Hz, ...): crc 0 accepted unchecked, ...' for the state_stream
    row ('' for a robot)."""
    unset = backend.unset_fields
    if unset is None:
        return ""
    filled = unset.describe_filled()
    return (f"; backend.simulator {unset.profile.name} ({unset.profile.state_rate_hz:.0f} Hz, robot needs "
            f"{launch.deploy.min_state_rate_hz:.0f}): " + (filled or "every field set, checked as a robot's"))


def _mode_machine_filled(backend) -> str:
    unset = backend.unset_fields
    if unset is None or "mode_machine" not in unset.filled:
        return ""
    return f" (left 0 by {unset.profile.name}: the launch file's expected_variant assumed)"


def format_table(results: list[CheckResult]) -> str:
    width = max(len(r.name) for r in results)
    lines = [f"{'check':<{width}}  {'result':<10}  reason", f"{'-' * width}  {'-' * 10}  {'-' * 40}"]
    for r in results:
        status = "OVERRIDDEN" if r.overridden else r.status.upper()
        lines.append(f"{r.name:<{width}}  {status:<10}  {r.reason}")
    return "\n".join(lines)


DRY_RUN_EXERCISE = (("stand", 2.0, 0.0, 0.0), ("forward", 4.0, 0.5, 0.0), ("turn", 2.0, 0.0, 0.5),
                    ("stand", 2.0, 0.0, 0.0))
"""(label, seconds, vx fraction of limits.max_vx_mps, wz fraction of limits.max_wz_radps) for a
dry run of a launch file whose commands come from an operator (unknown in advance)."""


def _dry_run_backend(launch: LaunchFile):
    """Lockstep MuJoCo of the robot the launch file is for (its variant and hands)."""
    from g1_control.launch.schema import BackendConfig

    b = launch.backend
    return BackendConfig(type="mujoco", mode="lockstep", physics_dt_s=b.physics_dt_s,
                         expected_variant=b.expected_variant, hands=b.hands)


def dry_run_launch(launch: LaunchFile, program=None) -> LaunchFile:
    """The same launch file on lockstep MuJoCo: same policy, rates, limits and safety thresholds; the
    behaviour program when there is one (`program`, or input.type program: run to its end), the
    scripted timeline when there is one, else a stand-walk-turn-stand exercise."""
    duration = launch.deploy.dry_run_s
    if program is not None or launch.input.type == "program":
        cfg = launch.input
        steps = [s.to_dict() for s in program.steps] if program is not None else list(cfg.program)
        text = "" if program is not None else cfg.instruction
        run_input = InputConfig(type="program", program=steps, instruction=text, places=dict(cfg.places),
                                pose="estimator", start_delay_s=cfg.start_delay_s)
        dry = dataclasses.replace(launch, name=f"{launch.name}-dry-run", duration_s=None, input=run_input,
                                  backend=_dry_run_backend(launch), viewer=False,
                                  estimation=dry_run_estimation(launch))
        dry.duration_s = max(duration, dry.total_duration_s)
        return dry
    if launch.input.type == "scripted":
        timeline = list(launch.input.timeline)
    else:
        lim = launch.limits
        timeline = [Segment(duration_s=s, vx_mps=round(fx * lim.max_vx_mps, 3), wz_radps=round(fw * lim.max_wz_radps, 3),
                            label=label) for label, s, fx, fw in DRY_RUN_EXERCISE]
    return dataclasses.replace(
        launch, name=f"{launch.name}-dry-run", duration_s=duration,
        backend=_dry_run_backend(launch),
        input=InputConfig(type="scripted", timeline=timeline), viewer=False, estimation=dry_run_estimation(launch))


def dry_run_estimation(launch: LaunchFile) -> EstimationConfig:
    """The dry run steers by what the robot will steer by: its own estimate (leg odometry) where the
    launch file does; no external pose (nothing publishes one to the simulated run)."""
    return EstimationConfig(steer_by="estimate" if launch.steers_by_estimate() else launch.estimation.steer_by)
