"""The one place a ControlLoop is assembled from a launch file.

    loop = build_loop(launch)                                   # g1 launch: MuJoCo + the launch file's input
    loop = build_loop(launch, backend=robot, input_device=remote,
                      wrap_tracker=deploy_state_machine)        # g1 deploy: the robot link
    loop = build_loop(dry_run_launch(launch))                   # the deploy preflight's dry run

`g1 launch`, `g1 deploy`, the preflight's dry run, the motion library's physics rollouts and the
WBC evaluation all call `build_loop`: the generator -> IK -> tracker chain (each stage built on its
own, from its own section: make_generator, make_ik, make_tracker), the rates, the safety filter
and the estimator come from the launch file alone. Only the backend (MuJoCo or a
robot link) and the input device may be handed in, and on the robot the deploy state machine
wraps the tracker. `loop.chain` names the stages, so a deploy can show that its dry run ran the
same chain as the robot (g1_control/deploy/session.py).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from typing import TYPE_CHECKING, Literal

from g1_control.errors import LaunchFileError
from g1_control.estimation.estimator import StateEstimator
from g1_control.interfaces import Backend, Generator, InputDevice, Tracker
from g1_control.launch.schema import SKELETON_GENERATORS, LaunchFile
from g1_control.launch.variant import check_tracker_fits, robot_variant
from g1_control.loop.control_loop import ControlLoop
from g1_control.safety import SafetyConfig, SafetyFilter
from g1_control.safety.fall import FallMonitor
from g1_control.teleop.scripted import Segment, random_timeline
from g1_control.types import CommandLimits

if TYPE_CHECKING:
    from g1_control.estimation.localiser import Localiser
    from g1_control.ik.stage import IKStage
    from g1_control.sim.mujoco_backend import MujocoBackend
    from g1_control.trackers.hands import HandsStage
    from g1_control.trackers.wbc.tracker import WbcConfig

CHAIN_STAGES = ("generator", "retargeter", "tracker", "rates", "safety")
"""The parts of `loop.chain` that must be the same in a deploy's dry run and on the robot."""


def safety_config(launch: LaunchFile) -> SafetyConfig:
    """The launch file's safety section, with limits.max_tilt_rad as a further cap on the tilt."""
    return dataclasses.replace(launch.safety, max_tilt_rad=min(launch.safety.max_tilt_rad,
                                                               launch.limits.max_tilt_rad))


def timeline_of(launch: LaunchFile) -> list[Segment]:
    """The command timeline when it is known in advance (scripted or random), else []."""
    if launch.input.type == "random":
        return random_timeline(launch.input.random, launch.total_duration_s)
    if launch.input.type == "scripted":
        return list(launch.input.timeline)
    return []


def wbc_config(launch: LaunchFile, footsteps: Literal["plan", "velocity"] = "plan") -> WbcConfig:
    """The whole-body controller's WbcConfig for this launch file: the tracker rate, the footsteps'
    source and the foot-floor friction it plans within (tracker.foot_friction)."""
    from g1_control.trackers.wbc.contacts import FootGeometry
    from g1_control.trackers.wbc.qp import QpConfig
    from g1_control.trackers.wbc.tracker import WbcConfig

    qp = QpConfig(foot=FootGeometry(friction=launch.tracker.foot_friction))
    return WbcConfig(rate_hz=launch.rates.tracker_hz, footsteps=footsteps, qp=qp)


def simulated_hands(backend) -> HandsStage | None:
    """The loop's finger stage for a simulated G1 with Dex3 hands (backend.hands: dex3): the
    reference's grasps and finger angles through the hands' safety layer on MuJoCo's fingers. None
    for any other backend: the robot's hands are driven over their own DDS topics (`g1 hands`)."""
    if not getattr(backend, "hand_sides", ()):  # MujocoBackend's, with Dex3 hands built
        return None
    from g1_control.safety.hands import GuardedHands
    from g1_control.sim.mujoco_hands import MujocoHandLink
    from g1_control.trackers.hands import HandsStage

    return HandsStage(GuardedHands(MujocoHandLink(backend), clock=lambda: backend.time_s))


def make_tracker(launch: LaunchFile) -> Tracker:
    cfg = launch.tracker
    check_tracker_fits(launch)  # a policy that does not fit the robot variant is refused by name
    if cfg.type == "policy":
        from g1_control.trackers.locomotion import LocomotionPolicyTracker, VelocityCorrectionConfig
        from g1_control.trackers.policy_spec import load_spec

        return LocomotionPolicyTracker(load_spec(cfg.policy), VelocityCorrectionConfig(enabled=cfg.velocity_correction),
                                       envelope_limits=cfg.envelope_limits)
    if cfg.type == "wbc":
        from g1_control.trackers.wbc.terrain import Terrain
        from g1_control.trackers.wbc.tracker import WholeBodyTracker

        # a scripted reference plans the feet; any other generator gives a root twist to walk
        config = wbc_config(launch, footsteps="plan" if launch.generator.type == "scripted" else "velocity")
        # its own gait steps onto the scene's platforms and stairs (a map, like the goals' scene)
        return WholeBodyTracker(config, variant=robot_variant(launch), hands=launch.backend.hands,
                                terrain=Terrain.of_scene(launch.scene))
    if cfg.type == "wbt":
        from g1_control.trackers.wbt import WbtPolicyTracker

        return WbtPolicyTracker()
    if cfg.type == "layer":
        from g1_control.trackers.layer import TrackingLayer
        from g1_control.trackers.locomotion import LocomotionPolicyTracker, VelocityCorrectionConfig
        from g1_control.trackers.policy_spec import load_spec
        from g1_control.trackers.wbc.tracker import WholeBodyTracker

        policy = LocomotionPolicyTracker(load_spec(cfg.policy), VelocityCorrectionConfig(enabled=cfg.velocity_correction),
                                         envelope_limits=cfg.envelope_limits)
        from g1_control.launch.schema import WBC_TRACKER_HZ
        from g1_control.trackers.wbc.terrain import Terrain

        # whole-body plans follow their own contacts; at 250 Hz and faster its gait walks with a held load
        # (layer.py); slower, a carry is whole-body steps (the gait carried worse at 100 Hz, measured)
        gait = launch.rates.tracker_hz >= WBC_TRACKER_HZ
        wbc = WholeBodyTracker(wbc_config(launch, footsteps="velocity" if gait else "plan"),
                               variant=robot_variant(launch), hands=launch.backend.hands,
                               terrain=Terrain.of_scene(launch.scene) if gait else None)
        return TrackingLayer(policy, wbc, launch.rates.tracker_hz)
    raise LaunchFileError(f"tracker.type: unknown tracker '{cfg.type}'")


def command_limits(launch: LaunchFile, tracker_limits: CommandLimits | None) -> CommandLimits:
    """The one source of operator velocity limits: the launch file's `limits` within the range the
    tracker can follow (Tracker.command_limits). Teleop sticks scale to it; the generator clamps to it."""
    lim = launch.limits
    limits = CommandLimits.symmetric(lim.max_vx_mps, lim.max_vy_mps, lim.max_wz_radps)
    return limits if tracker_limits is None else limits.intersect(tracker_limits)


def make_ik(launch: LaunchFile) -> IKStage:
    """The IK stage of the launch file's `ik:` section (g1_control/launch/schema.py: IKSection), one
    solve per tracker tick."""
    from g1_control.ik.exceptions import InvalidFrameError
    from g1_control.ik.retargeter import IKConfig
    from g1_control.ik.stage import IKStage

    section = dataclasses.asdict(launch.ik)
    stage = IKStage(IKConfig(dt_s=1.0 / launch.rates.tracker_hz, **section))
    for frame in launch.ik.frame_costs:
        try:
            stage.ik.configuration.frame_id(frame)
        except InvalidFrameError as exc:
            raise LaunchFileError(f"ik.frame_costs.{frame}: {exc}") from None
    return stage


def make_generator(launch: LaunchFile, limits: CommandLimits | None = None,
                   tracker: Tracker | None = None) -> Generator:
    """The generator; where the launch file executes goals (LaunchFile.executes_goals), the launch file's
    generator inside a GoalGenerator that executes task goals against the scene (g1_control/generator/goals/)."""
    cfg = launch.generator
    if cfg.type == "scripted":
        from g1_control.generator.scripted import TrajectoryGenerator, build_reference

        return TrajectoryGenerator(build_reference(cfg.reference, variant=launch.backend.expected_variant,
                                                   **cfg.reference_params))
    from g1_control.generator.factory import make_generator as make_named

    skeleton = "g1_29dof"
    if cfg.type in SKELETON_GENERATORS:
        from g1_control.generator.skeleton import skeleton_for_robot

        skeleton = skeleton_for_robot(launch.backend.expected_variant, launch.backend.hands)
    generator = make_named(cfg.type, model=cfg.model or None, limits=limits, skeleton=skeleton, feedback=cfg.feedback,
                           foot_lock=cfg.foot_lock)
    if not launch.executes_goals:
        return generator
    from g1_control.generator.goals.executor import GoalConfig, GoalGenerator
    from g1_control.trackers.layer import WBC_MIN_PELVIS_HEIGHT_M, TrackingLayer

    config = GoalConfig()
    # A plan pauses through a stall past the command's life on the robot link (3 tracker ticks where the hold is off).
    config.plan_pause_after_s = max(launch.safety.command_hold_ticks, 3) / launch.rates.tracker_hz
    # wall clock (a robot, a viewer): plans are made beside the loop; lockstep: inline (deterministic)
    config.plan_in_background = launch.backend.mode == "wallclock" or launch.backend.type != "mujoco"
    if isinstance(tracker, TrackingLayer):  # the walking policy's own height range (its envelope)
        config.policy_height_m = tracker.policy.command_limits.pelvis_height_m
        config.walk_while_holding = tracker.walks_holding()  # the WBC's gait carries (layer.py)
    if launch.tracker.type == "wbc":  # its gait walks at the heights asked, and with a held box
        config.policy_height_m = (WBC_MIN_PELVIS_HEIGHT_M, config.policy_height_m[1])
        config.walk_while_holding = True
    return GoalGenerator(generator, launch.scene, config)


def make_localiser(launch: LaunchFile, estimator: StateEstimator) -> Localiser | None:
    """The robot's world pose estimate when the launch file steers by it (estimation.steer_by; a robot
    link always does): leg odometry on the loop's estimator, fused with the external pose topic where
    estimation.external_pose names one. None: goals and programs steer by the simulator's ground truth."""
    if not launch.steers_by_estimate():
        return None
    from g1_control.estimation.external_pose import PoseFusion
    from g1_control.estimation.localiser import DdsPoseSource, Localiser
    from g1_control.estimation.pose import LegOdometry

    # the backend's partition by default: g1 deploy --partition isolates the topics with the robot link
    ext, seen = launch.estimation.external_pose, launch.estimation.perception
    fusion, source, objects = None, None, None
    if ext is not None:
        from g1_control.hardware.ros2.topics import PoseTopicReader

        assert ext.interface is not None  # validated: always named
        fusion = PoseFusion(ext)
        source = DdsPoseSource(PoseTopicReader(ext.interface, ext.domain, ext.topic,
                                               ext.partition or launch.backend.partition))
    if seen is not None:
        from g1_control.estimation.perception import DdsObjectSource, DdsPlatformSource, ObjectPerception
        from g1_control.hardware.ros2.topics import ObjectPosesReader, PlatformPosesReader

        assert seen.interface is not None  # validated: always named
        partition = seen.partition or launch.backend.partition
        objects = ObjectPerception(
            seen, DdsObjectSource(ObjectPosesReader(seen.interface, seen.domain, seen.topic, partition)),
            DdsPlatformSource(PlatformPosesReader(seen.interface, seen.domain, seen.platform_topic, partition)))
    return Localiser(LegOdometry(estimator, shared=True), fusion=fusion, source=source, objects=objects)


def make_sim_backend(launch: LaunchFile) -> MujocoBackend:
    if launch.backend.type != "mujoco":
        raise LaunchFileError(f"launch file '{launch.name}' drives a robot (backend.type {launch.backend.type}); "
                              "run it with `g1 deploy`, which checks the robot before anything moves")
    from g1_control.sim.mujoco_backend import MujocoBackend, MujocoConfig

    return MujocoBackend(MujocoConfig(physics_dt_s=launch.backend.physics_dt_s, lockstep=True,
                                      variant=launch.backend.expected_variant, hands=launch.backend.hands,
                                      randomize=launch.backend.randomize),
                         scene=launch.scene)


def describe_chain(launch: LaunchFile, generator: Generator, ik: IKStage, tracker: Tracker) -> dict[str, str]:
    g, t, r = launch.generator, launch.tracker, launch.rates
    what_generator = g.type + (f" {g.model}" if g.model else "") + (
        f" {g.reference} {g.reference_params}" if g.type == "scripted" else "")
    what_tracker = t.type + (f" {t.policy} (velocity correction {'on' if t.velocity_correction else 'off'})"
                             if t.type == "policy" else "")
    s = safety_config(launch)
    return {
        "generator": f"{type(generator).__name__} [{what_generator}]",
        "retargeter": ik.describe(),
        "tracker": f"{type(tracker).__name__} [{what_tracker}]",
        "rates": f"tracker {r.tracker_hz:g} Hz, input {r.input_hz:g} Hz, estimator {r.estimator_hz:g} Hz, "
                 f"low-level {r.lowlevel_hz:g} Hz",
        "safety": f"tilt {s.max_tilt_rad:g} rad, stale state {s.stale_state_s:g} s",
    }


def build_loop(launch: LaunchFile, *, backend: Backend | None = None, input_device: InputDevice | None = None,
               wrap_tracker: Callable[[Tracker, SafetyFilter], Tracker] | None = None, wallclock: bool | None = None,
               log_capacity: int | None = None) -> ControlLoop:
    """The loop `launch` describes.

    backend: the robot link (g1 deploy); default: MuJoCo in lockstep. input_device: default: the
    launch file's input section. wrap_tracker(tracker, safety): g1 deploy's state machine around the
    tracker (it is given the loop's safety filter, whose trips it follows).
    wallclock: default: the launch file's backend.mode (a robot link always runs on the wall clock).
    """
    from g1_control.launch.inputs import make_input

    tracker = make_tracker(launch)
    limits = command_limits(launch, tracker.command_limits)
    generator = make_generator(launch, limits, tracker)
    ik = make_ik(launch)
    chain = describe_chain(launch, generator, ik, tracker)
    if backend is None:
        backend = make_sim_backend(launch)
    if input_device is None:
        input_device = make_input(launch, timeline_of(launch), limits=limits, state_source=backend.read_state)
    safety = SafetyFilter(safety_config(launch))
    if wrap_tracker is not None:
        tracker = wrap_tracker(tracker, safety)
        chain["wrapper"] = type(tracker).__name__
    if wallclock is None:
        wallclock = launch.backend.mode == "wallclock" or not backend.lockstep
    r = launch.rates
    capacity = log_capacity if log_capacity is not None else int(launch.total_duration_s * r.tracker_hz) + 2
    estimator = StateEstimator()
    localiser = make_localiser(launch, estimator)
    if localiser is not None:
        generator.steer_by(localiser)
        chain["localiser"] = localiser.describe()
    hands = simulated_hands(backend)
    if hands is not None:
        chain["hands"] = "Dex3-1 (simulated fingers, GuardedHands)"
    goals = getattr(generator, "ctx", None)
    if goals is not None:  # a GoalGenerator: its finger grasps reach fingers only through a hands stage
        goals.fingers_driven = hands is not None
    loop = ControlLoop(backend, input_device, generator, ik, tracker, r, wallclock=wallclock,
                       safety=safety, log_capacity=capacity, estimator=estimator, localiser=localiser,
                       falls=FallMonitor(launch.fall, max_tilt_rad=safety.config.max_tilt_rad), hands=hands)
    chain["input"] = type(input_device).__name__
    chain["backend"] = backend.describe()
    loop.chain = chain
    return loop
