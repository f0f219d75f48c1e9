"""The preflight's checks besides the robot's, each verdict's exact words, without DDS or a simulation
(mutation-run survivors, issue 16): the launch file, the policy against the robot and the gain caps,
the link's interface, the operator input (a stand-in device), the dry run (a stand-in result), the
dry run's launch file, the refusal and the table."""

from __future__ import annotations

import dataclasses
from types import SimpleNamespace

import pytest
from deploy_test_helpers import write_launch

from g1_control.deploy import preflight as pf_module
from g1_control.deploy.preflight import FAIL, NOT_RUN, PASS, CheckResult, Preflight, dry_run_launch, format_table
from g1_control.errors import G1ControlError
from g1_control.interfaces import InputDevice
from g1_control.launch.schema import DeployConfig, InputConfig, load_launch
from g1_control.report.results import RunResult, SegmentResult
from g1_control.safety.config import SafetyConfig
from g1_control.trackers.policy_spec import load_spec
from g1_control.types import Command
from tests.paths import LAUNCH_DIR


@pytest.fixture(scope="module")
def launch_path(tmp_path_factory):
    return write_launch(tmp_path_factory.mktemp("pfp"))


@pytest.fixture(scope="module")
def launch(launch_path):
    return load_launch(launch_path)


def _only(pf: Preflight, name: str) -> CheckResult:
    others = {k for k, r in pf.results.items() if r.status != NOT_RUN}
    assert others <= {name}, others
    return pf.results[name]


# -- launch file -------------------------------------------------------------------------------------------
def test_a_robot_launch_file_passes_naming_backend_and_input(launch_path):
    pf = Preflight()
    launch = pf.check_launch_file(launch_path)
    assert launch is not None and launch.name == "sim2sim"
    r = _only(pf, "launch_file")
    assert (r.status, r.reason) == (PASS, f"{launch_path}: sim2sim (unitree_dds, input scripted)")


def test_a_simulator_launch_file_is_refused_for_good():
    pf = Preflight(frozenset({"launch_file"}))
    path = LAUNCH_DIR / "sim_walk.yaml"
    assert pf.check_launch_file(path) is None
    r = _only(pf, "launch_file")
    assert r.status == FAIL and r.overridable is False and not r.overridden and r.blocks
    assert r.reason == (f"{path}: backend.type is mujoco; g1 deploy drives a robot link (unitree_dds, can, serial). "
                        "Simulate with `g1 launch` (--override launch_file refused: this failure cannot be overridden)")


def test_a_missing_launch_file_is_refused(tmp_path):
    pf = Preflight()
    assert pf.check_launch_file(tmp_path / "none.yaml") is None
    r = _only(pf, "launch_file")
    assert (r.status, r.overridable, r.reason) == (FAIL, False, f"{tmp_path / 'none.yaml'}: no such launch file")


# -- policy --------------------------------------------------------------------------------------------
def test_the_shipped_policy_passes(launch):
    pf = Preflight()
    spec, variant = pf.check_policy(launch)
    assert spec is not None and spec.name == load_spec(launch.tracker.policy).name and variant == "g1_29dof"
    r = _only(pf, "policy")
    assert r.status == PASS
    assert r.reason == (f"{spec.name}: {len(spec.joint_names)} joints in G1 order, gains and default pose match the "
                        f"robot, ONNX {spec.onnx_path.name}, for g1_29dof")


def test_a_policy_for_another_variant_is_refused(launch):
    other = dataclasses.replace(launch, backend=dataclasses.replace(launch.backend, expected_variant="g1_23dof"))
    pf = Preflight()
    assert pf.check_policy(other) == (None, "g1_29dof")
    r = _only(pf, "policy")
    assert (r.status, r.overridable) == (FAIL, False)
    assert r.reason == (f"policy '{load_spec(launch.tracker.policy).name}' is for the g1_29dof G1 but backend.expected_variant is "
                        "g1_23dof; use a policy made for this robot")


def test_an_unknown_policy_is_refused(launch):
    other = dataclasses.replace(launch, tracker=dataclasses.replace(launch.tracker, policy="no_such_policy"))
    pf = Preflight()
    assert pf.check_policy(other) == (None, None)
    r = _only(pf, "policy")
    assert r.status == FAIL and r.overridable is False and "no_such_policy" in r.reason


@pytest.mark.parametrize("gain", ["kp", "kd"])
def test_policy_gains_above_the_safety_caps_are_refused(launch, gain):
    spec = load_spec(launch.tracker.policy)
    top = float(max(getattr(spec, gain)))
    caps = {"max_kp": top - 1.0} if gain == "kp" else {"max_kd": top - 0.5, "damping_kd": 0.1}
    other = dataclasses.replace(launch, safety=SafetyConfig(**caps))
    pf = Preflight()
    assert pf.check_policy(other) == (None, "g1_29dof")
    r = _only(pf, "policy")
    assert (r.status, r.overridable) == (FAIL, False)
    cap = top - 1.0 if gain == "kp" else top - 0.5
    assert r.reason == (f"policy '{spec.name}' uses {gain} up to {top:g} but safety.max_{gain} is {cap:g}: every "
                        "command would be clamped; raise the cap or lower the policy's gains")
    at_cap = {"max_kp": top} if gain == "kp" else {"max_kd": top, "damping_kd": 0.1}
    assert Preflight().check_policy(dataclasses.replace(launch, safety=SafetyConfig(**at_cap)))[0] is not None


# -- interface -------------------------------------------------------------------------------------------
def test_the_interface_check(launch):
    pf = Preflight()
    assert pf.check_interface(launch)
    r = _only(pf, "interface")
    assert (r.status, r.reason) == (PASS, "interface lo exists and is up (loopback: simulation)")
    missing = dataclasses.replace(launch, backend=dataclasses.replace(launch.backend, interface="g1nosuch0"))
    pf = Preflight()
    assert not pf.check_interface(missing)
    r = _only(pf, "interface")
    assert r.status == FAIL and r.overridable is False and "g1nosuch0" in r.reason


# -- operator input --------------------------------------------------------------------------------------
class _Device(InputDevice):
    """A stand-in input device: `lost` after `lose_after` polls (None: never), e-stop chords as given."""

    def __init__(self, chords=(("LB", "RB"),), lose_after=None, reason="unplugged"):
        self.buttons = {frozenset(c): "estop" for c in chords}
        self.buttons[frozenset({"A"})] = "run"
        self.polls, self.lose_after, self.reason = 0, lose_after, reason

    @property
    def lost(self) -> bool:
        return self.lose_after is not None and self.polls >= self.lose_after

    @property
    def lost_reason(self):
        return self.reason if self.lost else None

    def button_chords(self, action):
        return ["+".join(sorted(chord)) for chord, a in self.buttons.items() if a == action]

    def poll(self, now_s):
        self.polls += 1
        return Command()


def _teleop(launch, kind="gamepad", **backend):
    return dataclasses.replace(launch, input=InputConfig(type=kind),
                               deploy=dataclasses.replace(launch.deploy, input_check_s=0.05),
                               backend=dataclasses.replace(launch.backend, **backend))


def test_a_device_that_cannot_open_is_refused_for_good(launch):
    pf = Preflight(frozenset({"estop_input"}))
    assert not pf.check_input(None, launch, open_error="no gamepad at /dev/input/event9")
    r = _only(pf, "estop_input")
    assert r.status == FAIL and r.overridable is False and r.reason.startswith("no gamepad at /dev/input/event9")


@pytest.mark.parametrize("kind", ["scripted", "random", "gamepad_script", "program", "ros2"])
def test_inputs_without_an_operator_pass_only_against_the_emulator(launch, kind):
    pf = Preflight()
    assert pf.check_input(None, _teleop(launch, kind))
    assert _only(pf, "estop_input").status == PASS
    assert pf.results["estop_input"].reason == (f"{kind} input against the emulator on lo (sim2sim): no operator "
                                               "e-stop; Ctrl-C or SIGTERM damps")
    for backend in ({"interface": "eth0"}, {"type": "can", "can_interface": "virtual", "channel": "b"}):
        pf = Preflight()
        assert not pf.check_input(None, _teleop(launch, kind, **backend))
        r = _only(pf, "estop_input")
        assert r.status == FAIL and r.overridable
        assert r.reason == f"input.type {kind} has no operator e-stop; a robot needs unitree_remote, gamepad or keyboard"


def test_a_device_with_an_estop_passes_naming_its_chords(launch):
    pf = Preflight()
    device = _Device(chords=(("RB", "LB"), ("start",)))
    assert pf.check_input(device, _teleop(launch))
    assert device.polls >= 2
    r = _only(pf, "estop_input")
    assert (r.status, r.reason) == (PASS, "gamepad answering; e-stop on LB+RB, start")


def test_a_device_without_an_estop_fails_and_may_be_overridden(launch):
    pf = Preflight(frozenset({"estop_input"}))
    assert not pf.check_input(_Device(chords=()), _teleop(launch, "keyboard"))
    r = _only(pf, "estop_input")
    assert r.status == FAIL and r.overridden and not r.blocks
    assert r.reason == "keyboard mapping binds no button to estop; bind one in input.device.mapping.buttons"
    class Unmapped(InputDevice):  # maps no buttons at all (InputDevice.button_chords' default)
        def poll(self, now_s):
            return Command()

    pf = Preflight()
    assert not pf.check_input(Unmapped(), _teleop(launch))
    assert "binds no button to estop" in pf.results["estop_input"].reason


@pytest.mark.parametrize("lose_after", [0, 1, 2])
def test_a_device_lost_while_polled_is_refused_for_good(launch, lose_after):
    pf = Preflight(frozenset({"estop_input"}))
    device = _Device(lose_after=lose_after, reason="no events for 0.5 s")
    assert not pf.check_input(device, _teleop(launch, "unitree_remote"))
    r = _only(pf, "estop_input")
    assert r.status == FAIL and r.overridable is False and r.blocks
    assert r.reason.startswith("unitree_remote lost: no events for 0.5 s; reconnect it and start again")


def test_the_device_is_polled_once_more_after_the_listening_window(launch):
    no_window = dataclasses.replace(_teleop(launch), deploy=dataclasses.replace(launch.deploy, input_check_s=0.0))
    device = _Device(lose_after=1)
    pf = Preflight()
    assert not pf.check_input(device, no_window)
    assert device.polls == 1 and pf.results["estop_input"].reason.startswith("gamepad lost: unplugged")


# -- dry run (the simulation replaced by a stand-in result) -------------------------------------------------
def _result(fell=False, fall=None, events=(), program=None, segments=None):
    segments = segments if segments is not None else [
        SegmentResult("stand", 0.0, 1.0, (0.0, 0.0, 0.0), (0.01, 0.0, 0.0)),
        SegmentResult("forward", 1.0, 8.0, (0.5, 0.0, 0.0), (0.46, 0.0, 0.0)),
        SegmentResult("back", 8.0, 9.0, (-0.2, 0.0, 0.0), (-0.19, 0.0, 0.0))]
    return RunResult(name="x", fell=fell, duration_s=10.0, wall_s=3.25, segments=segments, timings={},
                     deadline_misses=0, overruns=0, events=list(events), estimator_rms_mps=None, fall=fall,
                     extra={} if program is None else {"program": program})


@pytest.fixture
def dry(monkeypatch):
    """Replace the simulation with a stand-in: set `box["result"]` (or an exception); the launch it got is kept."""
    import g1_control.launch.runner as runner

    box: dict = {}

    def fake_run(sim, progress=True, end_with_program=True):
        box["sim"], box["kwargs"] = sim, {"progress": progress, "end_with_program": end_with_program}
        if isinstance(box["result"], Exception):
            raise box["result"]
        return box["result"]

    monkeypatch.setattr(runner, "run", fake_run)
    return box


WHAT = "10.0 s lockstep MuJoCo of policy holosoma_loco_ppo at the launch file's rates (3.2 s wall)"
MOVED = "forward +0.46 m/s, back -0.19 m/s"


def test_a_dry_run_without_a_fall_passes(launch, dry):
    dry["result"] = _result()
    pf = Preflight()
    assert pf.check_dry_run(launch)
    r = _only(pf, "dry_run")
    assert (r.status, r.reason) == (PASS, f"no fall: {WHAT}; {MOVED}")
    assert pf.dry_run is dry["result"]
    assert dry["kwargs"] == {"progress": False, "end_with_program": False}
    assert dry["sim"].backend.type == "mujoco" and dry["sim"].name == "sim2sim-dry-run"
    dry["result"] = _result(segments=[])
    pf = Preflight()
    assert pf.check_dry_run(launch) and pf.results["dry_run"].reason == f"no fall: {WHAT}"


def test_a_fall_in_the_dry_run_fails_saying_when(launch, dry):
    dry["result"] = _result(fell=True, fall={"t_s": 4.26, "kind": "tilt", "detail": "pelvis tilted 1.10 rad"})
    pf = Preflight()
    assert not pf.check_dry_run(launch)
    r = _only(pf, "dry_run")
    assert r.status == FAIL and r.overridable
    assert r.reason == (f"FELL in simulation at 4.3 s (pelvis tilted 1.10 rad): {WHAT}; {MOVED}; do not run this "
                        "policy/launch file on the robot")
    dry["result"] = _result(fell=True)
    pf = Preflight()
    assert not pf.check_dry_run(launch)
    assert pf.results["dry_run"].reason.startswith(f"FELL in simulation: {WHAT}")


def _loop_events(*feed) -> list[dict]:
    """Events as a run's RunResult holds them: a real SafetyFilter's events, recorded as the loop records
    them (LoopEvent.of_safety), plus a loop event; `feed(filter)` calls in order."""
    from g1_control.loop.control_loop import LoopEvent
    from g1_control.safety import SafetyFilter

    events = [LoopEvent(0.5, "invalid_command", "Command.vx_mps is nan (damping keeps the last command)")]
    f = SafetyFilter(on_event=lambda e: events.append(LoopEvent.of_safety(e, e.t_s)))
    for step in feed:
        step(f)
    return [dataclasses.asdict(e) for e in events]


def test_a_safety_trip_in_the_dry_run_fails(launch, dry):
    events = _loop_events(lambda f: f.vet_input(Command(vx_mps=0.3), 1.0), lambda f: f.vet_input(None, 1.5),
                          lambda f: f.report_fall("pelvis tilted 1.10 rad (limit 1.00)", 4.0),
                          lambda f: f.estop("later", 5.0))
    assert [e["kind"] for e in events] == ["invalid_command", "input_stale", "fall"]
    dry["result"] = _result(events=events)
    pf = Preflight()
    assert not pf.check_dry_run(launch)
    assert _only(pf, "dry_run").reason == "the safety layer tripped in simulation: fall: pelvis tilted 1.10 rad (limit 1.00)"


def test_a_dry_run_whose_events_only_warn_passes(launch, dry):
    """Events that did not trip (an input gap, a loop event whose text says 'damping') are no fault."""
    dry["result"] = _result(events=_loop_events(lambda f: f.vet_input(Command(vx_mps=0.3), 1.0),
                                                lambda f: f.vet_input(None, 1.5)))
    pf = Preflight()
    assert pf.check_dry_run(launch) and _only(pf, "dry_run").status == PASS


def test_a_dry_run_that_cannot_run_fails(launch, dry):
    dry["result"] = G1ControlError("no such policy")
    pf = Preflight()
    assert not pf.check_dry_run(launch)
    assert _only(pf, "dry_run").reason == "the simulated dry run could not run: no such policy"
    assert pf.dry_run is None


def test_a_program_dry_run_reports_its_steps(launch, dry):
    steps = [{"label": "walk 1 m", "verdict": {"ok": True}}, {"label": "turn 90 deg", "verdict": {"ok": False}},
             {"label": "wave"}, {"label": "stand", "verdict": {"ok": False}}]
    dry["result"] = _result(segments=[], program={"finished": True, "steps": steps})
    pf = Preflight()
    assert pf.check_dry_run(launch)
    assert pf.results["dry_run"].reason == (f"no fall: {WHAT}; program finished, 4 steps, missed by ground truth: "
                                            "turn 90 deg, stand")
    dry["result"] = _result(segments=[], program={"finished": False, "steps": steps[:1]})
    pf = Preflight()
    assert not pf.check_dry_run(launch)
    assert pf.results["dry_run"].reason == f"the program did not finish in simulation: {WHAT}; program STOPPED, 1 steps"


# -- the dry run's launch file ----------------------------------------------------------------------------
def test_the_dry_run_of_a_scripted_launch_file_runs_its_timeline_on_lockstep_mujoco(launch):
    dry = dry_run_launch(launch)
    assert dry.name == "sim2sim-dry-run" and dry.duration_s == launch.deploy.dry_run_s and dry.viewer is False
    assert (dry.backend.type, dry.backend.mode, dry.backend.physics_dt_s) == ("mujoco", "lockstep", 0.002)
    assert dry.input.type == "scripted" and dry.input.timeline == launch.input.timeline
    assert dry.tracker == launch.tracker and dry.safety == launch.safety and dry.limits == launch.limits


def test_the_dry_run_of_an_operator_launch_file_is_the_exercise(launch):
    gamepad = dataclasses.replace(launch, input=InputConfig(type="gamepad"),
                                  backend=dataclasses.replace(launch.backend, physics_dt_s=0.001))
    dry = dry_run_launch(gamepad)
    assert dry.backend.physics_dt_s == 0.001 and dry.input.type == "scripted"
    got = [(s.label, s.duration_s, s.vx_mps, s.vy_mps, s.wz_radps) for s in dry.input.timeline]
    assert got == [("stand", 2.0, 0.0, 0.0, 0.0), ("forward", 4.0, 0.4, 0.0, 0.0), ("turn", 2.0, 0.0, 0.0, 0.5),
                   ("stand", 2.0, 0.0, 0.0, 0.0)]
    odd = dataclasses.replace(gamepad, limits=dataclasses.replace(launch.limits, max_vx_mps=0.7777, max_wz_radps=0.3333))
    assert [(s.vx_mps, s.wz_radps) for s in dry_run_launch(odd).input.timeline][1:3] == [(0.389, 0.0), (0.0, 0.167)]


def test_the_dry_run_of_a_program_runs_the_program_to_its_end(launch):
    steps = [{"kind": "walk", "distance_m": 1.0}, {"kind": "turn", "angle_rad": 1.5708}]
    prog = dataclasses.replace(launch, input=InputConfig(type="program", program=steps, start_delay_s=0.5,
                                                         places={"door": {"pos_w_m": [3, 0, 0]}}, pose="ground_truth"),
                               deploy=DeployConfig(dry_run_s=10.0))
    dry = dry_run_launch(prog)
    assert dry.input.type == "program" and dry.input.program == steps and dry.input.instruction == ""
    assert dry.input.pose == "estimator" and dry.input.start_delay_s == 0.5 and dry.input.places == prog.input.places
    assert dry.input.places is not prog.input.places
    assert dry.backend.type == "mujoco" and dry.viewer is False and dry.name == "sim2sim-dry-run"
    assert dry.duration_s == max(10.0, dry.total_duration_s) and dry.duration_s > 10.0
    said = dataclasses.replace(prog, input=InputConfig(type="program", instruction="wave"))
    assert dry_run_launch(said).input.instruction == "wave"
    short = dry_run_launch(dataclasses.replace(prog, deploy=DeployConfig(dry_run_s=500.0)))
    assert short.duration_s == 500.0
    given = dry_run_launch(launch, program=prog.input.parsed_program())
    assert [s["kind"] for s in given.input.program] == ["walk", "turn"] and given.input.instruction == ""


# -- verdict ---------------------------------------------------------------------------------------------
def test_the_refusal_names_the_blocking_checks_and_what_may_be_overridden():
    pf = Preflight(frozenset({"battery"}))
    for name in pf.results:
        pf.record(name, PASS, "ok")
    assert pf.passed
    pf.record("temperatures", FAIL, "hot")
    pf.record("variant", FAIL, "other robot", overridable=False)
    pf.record("battery", FAIL, "low")
    pf.not_run(["dry_run"], "x")
    pf.results["dry_run"] = CheckResult("dry_run", NOT_RUN, "not run: x")
    assert not pf.passed
    assert str(pf.refusal()) == ("preflight failed (variant, temperatures, dry_run): nothing was sent to the robot; "
                                 "fix them, or override a check you have verified yourself with --override NAME "
                                 "(overridable here: temperatures)")
    pf.record("temperatures", PASS, "ok")
    assert str(pf.refusal()) == "preflight failed (variant, dry_run): nothing was sent to the robot; fix them first"


def test_the_table():
    rows = [CheckResult("policy", PASS, "fine"), CheckResult("battery", FAIL, "low", overridden=True),
            CheckResult("dry_run", NOT_RUN, "not run")]
    assert format_table(rows) == ("check    result      reason\n"
                                  "-------  ----------  ----------------------------------------\n"
                                  "policy   PASS        fine\n"
                                  "battery  OVERRIDDEN  low\n"
                                  "dry_run  NOT RUN     not run")
    pf = Preflight()
    assert pf.table() == format_table(list(pf.results.values()))
    assert pf.as_dict()[0] == {"name": "launch_file", "status": NOT_RUN, "reason": "not run", "overridable": True,
                               "overridden": False}
    assert [n for n in pf_module.CHECKS if n not in pf_module.OPTIONAL_CHECKS] == [r["name"] for r in pf.as_dict()]
    pf.record("finger_limits", PASS, "fine")  # an optional row takes its place in CHECKS order
    assert [r["name"] for r in pf.as_dict()][-4:] == ["battery", "finger_limits", "estop_input", "dry_run"]


def test_the_device_is_polled_throughout_the_window_with_the_time(launch, monkeypatch):
    now = [50.0]
    monkeypatch.setattr(pf_module, "time", SimpleNamespace(monotonic=lambda: now[0],
                                                           sleep=lambda s: now.__setitem__(0, now[0] + s)))
    seen = []
    device = _Device()
    device.poll = lambda t: seen.append(round(t - 50.0, 6))
    assert Preflight().check_input(device, _teleop(launch))  # input_check_s 0.05: polls at 0, 0.02, 0.04, then once more
    assert seen == [0.0, 0.02, 0.04, 0.06]


def test_a_lost_device_without_a_reason_says_so(launch):
    class Lost(_Device):
        lost_reason = None

    device = Lost(chords=(("B",),), lose_after=0)
    pf = Preflight()
    assert not pf.check_input(device, _teleop(launch))
    assert pf.results["estop_input"].reason == "gamepad lost: ?; reconnect it and start again"


def test_the_dry_run_runs_the_program_it_is_given(launch, dry):
    from g1_control.program import parse_instruction

    dry["result"] = _result(segments=[], program={"finished": True, "steps": []})
    assert Preflight().check_dry_run(launch, parse_instruction("walk forward 1 m"))
    assert dry["sim"].input.type == "program" and [s["kind"] for s in dry["sim"].input.program] == ["walk"]


def test_the_dry_run_never_opens_a_viewer_and_keeps_the_physics_step(launch):
    shown = dataclasses.replace(launch, viewer=True, backend=dataclasses.replace(launch.backend, physics_dt_s=0.001))
    assert dry_run_launch(shown).viewer is False
    said = dataclasses.replace(shown, input=InputConfig(type="program", instruction="walk forward 1 m"))
    dry = dry_run_launch(said)
    assert dry.viewer is False and dry.input.instruction == "walk forward 1 m"
    assert (dry.backend.type, dry.backend.mode, dry.backend.physics_dt_s) == ("mujoco", "lockstep", 0.001)
    given = dry_run_launch(said, program=said.input.parsed_program())
    assert given.input.instruction == "" and [s["kind"] for s in given.input.program] == ["walk"]
