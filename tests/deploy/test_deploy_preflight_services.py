"""The preflight's rows that had no fast test (mutation-run survivors and "no tests", issue 26), each
verdict's exact words, status and overridable flag, without DDS or a simulation: the motion-service
row on a stand-in service (asked with CheckMode only, on the link's participant and partition, for
MOTION_SERVICE_WAIT_S; on a stand-in clock), the model-based controller's policy row, the notes on goals
placed by the robot's own estimate, the dry run's robot (variant, hands) and what it steers by, a
segment the dry run did not reach, and the table's rows of other names (g1 doctor's)."""

from __future__ import annotations

import dataclasses
from types import SimpleNamespace
from typing import ClassVar

import numpy as np
import pytest
from deploy_test_helpers import write_launch

from g1_control.deploy import preflight as pf_module
from g1_control.deploy.preflight import DEBUG_MODE, FAIL, NOT_RUN, PASS, SKIP, Preflight, dry_run_launch
from g1_control.errors import MotionServiceError
from g1_control.estimation.external_pose import ExternalPoseConfig
from g1_control.hardware.links.dds import DdsLink
from g1_control.launch.schema import EstimationConfig, InputConfig, load_launch
from g1_control.report.results import RunResult, SegmentResult
from tests.paths import LAUNCH_DIR

SIM2SIM_GOALS = LAUNCH_DIR / "sim2sim_goals.yaml"


@pytest.fixture(scope="module")
def launch(tmp_path_factory):
    """launch/sim2sim.yaml: unitree_dds on lo, the walking policy, a scripted timeline."""
    return load_launch(write_launch(tmp_path_factory.mktemp("pfsv")))


def _backend(launch, **changes):
    return dataclasses.replace(launch, backend=dataclasses.replace(launch.backend, **changes))


# -- motion service ---------------------------------------------------------------------------------------
class _DdsLink(DdsLink):
    """A DdsLink (the check asks only DDS links) with no DDS behind it: a participant to hand on."""

    def __init__(self):  # no super().__init__: nothing is opened
        pass

    @property
    def participant(self):
        return "the link's participant"

    def describe(self) -> str:
        return "stand-in DDS link"


class _Service:
    """Stands in for MotionServiceClient: answers CheckMode with `mode`, or stays silent (the clock
    runs for the client's timeout) and raises; records how it was made and what it was asked."""

    made: ClassVar[list] = []
    clock: ClassVar[list] = [0.0]
    answer: ClassVar[object] = ""

    instances: ClassVar[list] = []

    def __init__(self, participant, partition=None, timeout_s=1.0):
        self.made.append((participant, partition, timeout_s))
        self.instances.append(self)
        self.asked: list[str] = []
        self.timeout_s = timeout_s

    def check_mode(self):
        answer = self.answer
        self.asked.append("check_mode")
        if isinstance(answer, Exception):
            self.clock[0] += self.timeout_s
            raise answer
        return answer

    def release_mode(self):  # never: the preflight only asks
        raise AssertionError("the preflight released the motion service")

    def close(self):
        self.asked.append("close")


@pytest.fixture
def service(monkeypatch):
    """`service.answer = "ai"` (active controller), "" (none), or a MotionServiceError (silent)."""
    import g1_control.hardware.unitree.motion_service as motion_service

    now = [10.0]
    monkeypatch.setattr(pf_module, "time", SimpleNamespace(monotonic=lambda: now[0],
                                                           sleep=lambda s: now.__setitem__(0, now[0] + s)))
    _Service.made, _Service.instances = [], []
    _Service.clock = now
    _Service.answer = ""
    monkeypatch.setattr(motion_service, "MotionServiceClient", _Service)
    return _Service


SILENT = MotionServiceError("the robot's motion service did not answer api 1001 within 1.0 s")


def _ask(launch, link=None):
    pf = Preflight(frozenset({"motion_service"}))  # overridden where it may be: every refusal below may not
    made = len(_Service.made)
    ok = pf.check_motion_service(SimpleNamespace(link=link or _DdsLink()), launch)
    asked = [client.asked for client in _Service.instances[made:]]
    assert all(a == ["check_mode", "close"] for a in asked), f"each client asked once, then closed: {asked}"
    return ok, pf.results["motion_service"]


def test_the_service_is_asked_on_the_links_participant_and_partition_for_one_second(launch, service):
    ok, r = _ask(_backend(launch, partition="g1test"))
    assert ok and (r.status, r.reason) == (PASS, "no built-in controller active: ready for low-level control")
    assert service.made == [("the link's participant", "g1test", pf_module.MOTION_SERVICE_WAIT_S)]
    assert pf_module.MOTION_SERVICE_WAIT_S == 1.0


def test_an_active_controller_passes_when_g1_deploy_releases_it(launch, service):
    service.answer = "ai"
    ok, r = _ask(_backend(launch, release_motion_service=True))
    assert ok and (r.status, r.reason) == (PASS, "built-in controller 'ai' active; g1 deploy will release it "
                                                 "(ReleaseMode) before it sends anything")


def test_an_active_controller_without_the_release_is_refused_for_good(launch, service):
    service.answer = "ai"
    ok, r = _ask(_backend(launch, release_motion_service=False))
    assert not ok and (r.status, r.overridable, r.overridden, r.blocks) == (FAIL, False, False, True)
    assert r.reason == ("built-in controller 'ai' active and backend.release_motion_service is false: the robot would "
                        f"mix its own commands with ours. {DEBUG_MODE} (--override motion_service refused: this "
                        "failure cannot be overridden)")


def test_a_silent_service_is_refused_when_the_release_would_fail(launch, service):
    service.answer = SILENT
    ok, r = _ask(_backend(launch, release_motion_service=True))
    assert not ok and (r.status, r.overridable, r.blocks) == (FAIL, False, True)
    assert r.reason == ("no motion service answered within 1.0 s, and backend.release_motion_service is true: the "
                        "release would fail before control starts. If the robot is in debug mode already (L2+R2 on its "
                        "remote), skip the release: --no-release-motion-service (or backend.release_motion_service: "
                        f"false) ({SILENT}) (--override motion_service refused: this failure cannot be overridden)")


def test_a_silent_service_without_the_release_is_debug_mode(launch, service):
    service.answer = SILENT
    ok, r = _ask(_backend(launch, release_motion_service=False))
    assert ok and (r.status, r.reason) == (SKIP, "no motion service answered within 1.0 s: debug mode assumed "
                                                 "(backend.release_motion_service false)")


def test_links_and_simulators_without_a_motion_service_are_not_asked(launch, service):
    ok, r = _ask(launch, link=SimpleNamespace(describe=lambda: "CAN (virtual, channel b)"))
    assert ok and (r.status, r.reason) == (SKIP, "CAN (virtual, channel b) has no motion service to ask")
    ok, r = _ask(_backend(launch, simulator="unitree_mujoco"))
    assert ok and (r.status, r.reason) == (SKIP, "backend.simulator unitree_mujoco: a simulator runs no motion "
                                                 "service; nothing is released")
    assert service.made == []


# -- the model-based controller -------------------------------------------------------------------------
@pytest.mark.parametrize(("variant", "joints"), [("g1_29dof", 29), ("g1_23dof", 23)])
def test_the_model_based_controller_needs_no_policy_and_runs_the_launch_files_variant(launch, variant, joints):
    wbc = dataclasses.replace(_backend(launch, expected_variant=variant),
                              tracker=dataclasses.replace(launch.tracker, type="wbc", policy="no_such_policy"))
    pf = Preflight()
    assert pf.check_policy(wbc) == (None, variant)
    r = pf.results["policy"]
    assert (r.status, r.reason) == (PASS, f"tracker.type wbc: no learned policy; the model-based controller runs the "
                                          f"{variant} model ({joints} joints)")


# -- goals placed by the robot's own estimate ---------------------------------------------------------------
def test_a_goal_at_a_world_point_is_noted_in_the_launch_file_row():
    pf = Preflight()
    assert pf.check_launch_file(SIM2SIM_GOALS) is not None
    r = pf.results["launch_file"]
    assert (r.status, r.reason) == (PASS, f"{SIM2SIM_GOALS}: sim2sim-goals (unitree_dds, input scripted); note: goal "
                                          "seg2.0 (reach left hand at (0.40, 0.20, 0.95)) is placed by the robot's own "
                                          "estimate (leg odometry, anchored where it starts: the scene's origin, "
                                          "facing +x)")


def test_every_placed_goal_is_noted_naming_the_external_pose(tmp_path):
    timeline = [{"duration_s": 2, "label": "a", "goals": [{"kind": "reach", "hand": "left", "pos_w_m": [0.4, 0.2, 0.9]}]},
                {"duration_s": 2, "label": "b", "goals": [{"kind": "reach", "hand": "right", "offset_h_m": [0.2, 0, 0]},
                                                          {"kind": "reach", "hand": "right", "pos_w_m": [0.5, -0.2, 1.0]}]}]
    path = write_launch(tmp_path, {"input": {"timeline": timeline},
                                   "estimation": {"external_pose": {"topic": "mocap/pose", "interface": "lo", "domain": 1}}},
                        base=SIM2SIM_GOALS)
    pf = Preflight()
    assert pf.check_launch_file(path) is not None
    note = ("; note: goal {} ({}) is placed by the robot's own estimate (leg odometry fused with the external pose, "
            "anchored where it starts: the scene's origin, facing +x)")
    assert pf.results["launch_file"].reason == (
        f"{path}: sim2sim-goals (unitree_dds, input scripted)"
        + note.format("seg0.0", "reach left hand at (0.40, 0.20, 0.90)")
        + note.format("seg1.1", "reach right hand at (0.50, -0.20, 1.00)"))


# -- the dry run's robot and estimate -------------------------------------------------------------------------
@pytest.mark.parametrize(("variant", "hands"), [("g1_23dof", "none"), ("g1_29dof", "dex3")])
def test_the_dry_run_simulates_the_launch_files_robot(launch, variant, hands):
    robot = _backend(launch, expected_variant=variant, hands=hands)
    programmed = dataclasses.replace(robot, input=InputConfig(type="program", instruction="walk forward 1 m"))
    for dry in (dry_run_launch(robot), dry_run_launch(programmed)):
        b = dry.backend
        assert (b.type, b.mode, b.expected_variant, b.hands) == ("mujoco", "lockstep", variant, hands)


def test_the_dry_run_of_a_robot_launch_file_steers_by_the_estimate_without_the_external_pose(launch):
    mocap = dataclasses.replace(launch, estimation=EstimationConfig(external_pose=ExternalPoseConfig(interface="lo")))
    programmed = dataclasses.replace(mocap, input=InputConfig(type="program", instruction="walk forward 1 m"))
    assert launch.estimation.steer_by == "auto"
    for dry in (dry_run_launch(launch), dry_run_launch(mocap), dry_run_launch(programmed)):
        assert dry.estimation == EstimationConfig(steer_by="estimate")
        assert dry.estimation.external_pose is None and dry.estimation.perception is None


@pytest.mark.parametrize("steer_by", ["auto", "ground_truth", "estimate"])
def test_the_dry_run_of_a_simulator_launch_file_steers_by_what_it_says(launch, steer_by):
    sim = dataclasses.replace(_backend(launch, type="mujoco"), estimation=EstimationConfig(steer_by=steer_by))
    assert dry_run_launch(sim).estimation == EstimationConfig(steer_by=steer_by)
    programmed = dataclasses.replace(sim, input=InputConfig(type="program", instruction="walk forward 1 m"))
    assert dry_run_launch(programmed).estimation == EstimationConfig(steer_by=steer_by)


# -- the dry run's verdict ------------------------------------------------------------------------------------
@pytest.fixture
def dry(monkeypatch):
    """The simulation replaced by a stand-in: `box["result"]` is what it returns."""
    import g1_control.launch.runner as runner

    box: dict = {}
    monkeypatch.setattr(runner, "run", lambda sim, progress=True, end_with_program=True: box["result"])
    return box


def _result(segments):
    return RunResult(name="x", fell=False, duration_s=10.0, wall_s=3.25, segments=segments, timings={},
                     deadline_misses=0, overruns=0, events=[], estimator_rms_mps=None)


def test_the_dry_run_of_the_model_based_controller_names_it_and_an_unreached_segment(launch, dry):
    nan = float("nan")
    dry["result"] = _result([SegmentResult("walk", 0.0, 8.0, (0.5, 0.0, 0.0), (0.47, 0.01, 0.0)),
                             SegmentResult("back", 12.0, 14.0, (-0.2, 0.0, 0.0), (nan, nan, nan))])
    wbc = dataclasses.replace(_backend(launch, expected_variant="g1_23dof"),
                              tracker=dataclasses.replace(launch.tracker, type="wbc"))
    pf = Preflight()
    assert pf.check_dry_run(wbc)
    assert pf.results["dry_run"].reason == (
        "no fall: 10.0 s lockstep MuJoCo of the model-based controller on the g1_23dof G1 at the launch file's rates "
        "(3.2 s wall); walk +0.47 m/s, back not reached (starts at 12.0 s, the dry run ran 10.0 s)")
    assert np.isnan(dry["result"].segments[1].achieved).all()


# -- rows -----------------------------------------------------------------------------------------------------
def test_rows_of_other_names_stay_when_an_optional_row_is_added():
    pf = Preflight()
    pf.record("domain", PASS, "the robot publishes on domain 0")  # g1 doctor's row
    pf.record("hands_present", FAIL, "no HandState_ from the left hand")
    names = list(pf.results)
    assert names[-1] == "domain" and names.index("hands_present") == names.index("battery") + 1
    assert pf.results["domain"].reason == "the robot publishes on domain 0"


def test_not_run_marks_only_rows_nothing_has_judged():
    pf = Preflight()
    pf.record("peers", PASS, "one publisher")
    pf.record("battery", FAIL, "low")
    pf.not_run(["peers", "battery", "imu_upright", "finger_limits"], "no robot state")
    got = {n: (pf.results[n].status, pf.results[n].reason) for n in ("peers", "battery", "imu_upright", "finger_limits")}
    assert got == {"peers": (PASS, "one publisher"), "battery": (FAIL, "low"),
                   "imu_upright": (NOT_RUN, "not run: no robot state"),
                   "finger_limits": (NOT_RUN, "not run: no robot state")}
    pf.not_run(["imu_upright"], "again")
    assert pf.results["imu_upright"].reason == "not run: again"
