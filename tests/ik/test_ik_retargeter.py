import numpy as np
import pinocchio as pin
import pytest

from g1_control.ik.exceptions import InvalidFrameError, InvalidReferenceError, NoSolutionFound, TaskDefinitionError
from g1_control.ik.retargeter import IKConfig, IKRetargeter
from g1_control.interfaces import Retargeter
from g1_control.robot import g1
from g1_control.types import JointReference, KinematicReference


def _pose7(p: pin.SE3) -> np.ndarray:
    q = pin.Quaternion(p.rotation)
    return np.array([*p.translation, q.w, q.x, q.y, q.z])


def _reference(ik: IKRetargeter, hand_offset=(0.0, 0.0, 0.0), contacts=(True, True)) -> KinematicReference:
    conf = ik.configuration
    hand = pin.SE3(conf.frame_placement(conf.frame_id("left_rubber_hand")))
    hand.translation = hand.translation + np.asarray(hand_offset)
    return KinematicReference(root_pos_w_m=np.array([0.0, 0.0, g1.DEFAULT_PELVIS_HEIGHT_M]),
                              q_rad=np.asarray(g1.DEFAULT_Q_RAD).copy(),
                              frame_targets_w={"left_rubber_hand": _pose7(hand)},
                              contacts=np.array(contacts))


def test_is_a_retargeter_and_returns_a_joint_reference():
    ik = IKRetargeter()
    assert isinstance(ik, Retargeter)
    out = ik.solve(_reference(ik), np.asarray(g1.DEFAULT_Q_RAD))
    assert isinstance(out, JointReference)
    assert out.q_rad.shape == (29,) and out.dq_radps.shape == (29,)
    assert abs(np.linalg.norm(out.root_quat_wxyz) - 1.0) < 1e-9
    assert out.contacts.tolist() == [True, True]


def test_reaches_a_hand_target_with_feet_held_and_on_the_ground():
    ik = IKRetargeter(IKConfig(frame_costs={"left_rubber_hand": (50.0, 0.0)}))
    q = np.asarray(g1.DEFAULT_Q_RAD).copy()
    out = ik.solve(_reference(ik), q)  # touchdown: feet put level on the ground ...
    for _ in range(4):  # ... reached over a few ticks (one QP step is a linearisation)
        out = ik.solve(_reference(ik), out.q_rad)
    feet = [pin.SE3(ik.configuration.frame_placement(ik.configuration.frame_id(f))) for f in g1.FOOT_BODIES]
    ref = _reference(ik, hand_offset=(0.15, 0.0, 0.15))
    for _ in range(60):
        out = ik.solve(ref, out.q_rad)
    conf = ik.configuration
    hand = conf.frame_placement(conf.frame_id("left_rubber_hand")).translation
    np.testing.assert_allclose(hand, ref.frame_targets_w["left_rubber_hand"][:3], atol=5e-3)
    for foot, before in zip(g1.FOOT_BODIES, feet):
        now = conf.frame_placement(conf.frame_id(foot))
        np.testing.assert_allclose(now.translation, before.translation, atol=1e-5)
    assert ik.ground_limit.point_heights(conf).min() > -1e-6
    # touched down level on the ground: sole spheres at height 0
    assert ik.ground_limit.point_heights(conf).max() < 1e-4


def test_joint_speed_never_exceeds_the_motor_limits():
    ik = IKRetargeter(IKConfig(velocity_limit_scale=0.2, hold_contacts=False))
    q = np.asarray(g1.DEFAULT_Q_RAD).copy()
    far = _reference(ik, hand_offset=(0.3, 0.2, 0.4), contacts=(False, False))
    for _ in range(10):
        out = ik.solve(far, q)
        assert np.all(np.abs(out.q_rad - q) <= 0.2 * g1.VELOCITY_LIMIT_RADPS * 0.02 + 1e-7)
        np.testing.assert_allclose(out.dq_radps, (out.q_rad - q) / 0.02, atol=1e-9)
        q = out.q_rad


def test_multiple_iterations_per_tick_share_one_velocity_budget():
    ik = IKRetargeter(IKConfig(iterations=4, velocity_limit_scale=0.1, hold_contacts=False))
    q = np.asarray(g1.DEFAULT_Q_RAD).copy()
    out = ik.solve(_reference(ik, hand_offset=(0.3, 0.2, 0.4), contacts=(False, False)), q)
    assert np.all(np.abs(out.q_rad - q) <= 0.1 * g1.VELOCITY_LIMIT_RADPS * 0.02 + 1e-7)


def test_joint_limits_hold_for_unreachable_targets():
    ik = IKRetargeter(IKConfig(hold_contacts=False))
    q = np.asarray(g1.DEFAULT_Q_RAD).copy()
    ref = _reference(ik, hand_offset=(2.0, 2.0, 2.0), contacts=(False, False))
    for _ in range(40):
        q = ik.solve(ref, q).q_rad
        assert np.all(q >= g1.Q_MIN_RAD - 1e-9) and np.all(q <= g1.Q_MAX_RAD + 1e-9)


def test_bad_references_are_refused_by_name():
    ik = IKRetargeter()
    ref = _reference(ik)
    ref.q_rad[3] = np.nan
    with pytest.raises(InvalidReferenceError, match="q_rad contains NaN"):
        ik.solve(ref, np.asarray(g1.DEFAULT_Q_RAD))
    ref = _reference(ik)
    ref.frame_targets_w["left_hoof"] = ref.frame_targets_w["left_rubber_hand"]
    with pytest.raises(InvalidFrameError, match="no frame 'left_hoof'"):
        ik.solve(ref, np.asarray(g1.DEFAULT_Q_RAD))
    with pytest.raises(InvalidReferenceError, match=r"q_prev has shape \(12,\)"):
        ik.solve(_reference(ik), np.zeros(12))
    ref = _reference(ik)
    ref.frame_targets_w["left_rubber_hand"] = np.zeros(3)
    with pytest.raises(InvalidReferenceError, match="frame target 'left_rubber_hand' must be 7 finite numbers"):
        ik.solve(ref, np.asarray(g1.DEFAULT_Q_RAD))


def test_config_is_validated():
    with pytest.raises(TaskDefinitionError, match="backend must be one of"):
        IKRetargeter(IKConfig(backend="osqp"))
    with pytest.raises(TaskDefinitionError, match="iterations must be >= 1"):
        IKRetargeter(IKConfig(iterations=0))


def test_smoothness_reduces_jitter_on_a_noisy_target():
    def jitter(cost):
        ik = IKRetargeter(IKConfig(smoothness_cost=cost, hold_contacts=False))
        rng = np.random.default_rng(0)
        q = np.asarray(g1.DEFAULT_Q_RAD).copy()
        qs = []
        for _ in range(60):
            q = ik.solve(_reference(ik, hand_offset=0.01 * rng.standard_normal(3), contacts=(False, False)), q).q_rad
            qs.append(q)
        return np.abs(np.diff(np.array(qs), n=2, axis=0)).mean()

    assert jitter(1.0) < 0.8 * jitter(0.0)


def test_projection_step_keeps_held_feet_in_place_on_big_steps():
    def drift(tolerance):
        ik = IKRetargeter(IKConfig(dt_s=0.1, contact_tolerance_m=tolerance, root_cost=(50.0, 5.0), com_cost=(0, 0, 0)))
        ref = _reference(ik)
        q = np.asarray(g1.DEFAULT_Q_RAD).copy()
        for _ in range(5):  # settle the feet on the ground
            q = ik.solve(ref, q).q_rad
        conf = ik.configuration
        before = conf.frame_placement(conf.frame_id("left_ankle_roll_link")).translation.copy()
        crouch = _reference(ik)
        crouch.root_pos_w_m = ref.root_pos_w_m - np.array([0.0, 0.0, 0.18])  # a deep crouch in one tick
        ik.solve(crouch, q)
        return np.linalg.norm(conf.frame_placement(conf.frame_id("left_ankle_roll_link")).translation - before)

    assert drift(0.0) > 3e-3  # one linearised step alone lets the foot drift by millimetres
    assert drift(1e-3) < 1e-3


def test_touchdown_on_a_box_top_snaps_the_foot_onto_it():
    """A stance foot landing 1.5 cm inside a low box is anchored on the box's top, not in it."""
    from g1_control.ik.limits import GroundLimit
    from g1_control.motion.objects import ObjectShape

    probe = IKRetargeter()
    foot = probe.configuration.frame_placement(probe.configuration.frame_id("left_ankle_roll_link")).translation
    top = 0.015
    box = ObjectShape.box("plate", (0.2, 0.1, top / 2)).transformed(np.eye(3), np.array([foot[0], foot[1], top / 2]))
    ik = IKRetargeter(IKConfig(scene=(box,)))
    out = ik.solve(_reference(ik), np.asarray(g1.DEFAULT_Q_RAD))
    for _ in range(10):
        out = ik.solve(_reference(ik), out.q_rad)
    left = ik.contacts[0]
    assert left.active
    np.testing.assert_allclose(left.anchor.translation[2] - ik._sole_depth["left_ankle_roll_link"], top, atol=1e-9)
    clearance = GroundLimit(scene=(box,)).scene_clearances(ik.configuration)
    assert clearance.min() > -1e-3  # the left foot came up out of the plate
    heights = ik.ground_limit.point_heights(ik.configuration)
    assert heights[:4].min() == pytest.approx(top, abs=2e-3) and heights[4:].max() < 1e-4  # right foot on the floor


def _elbow_into_chest(resolve: bool, refine: bool = False) -> float:
    # At 30 Hz the velocity limits let the shoulder turn 1.2 rad in one step: the elbow, clear of
    # the chest by more than the activation distance (so no row in the QP), is pulled toward a
    # target inside the chest. Returns the deepest self-overlap after one tick.
    ik = IKRetargeter(IKConfig(dt_s=1 / 30, self_collision=True, com_cost=(0.0, 0.0, 0.0), hold_contacts=False,
                               enforce_ground=False, scene_collision=False, projection_steps=4 if refine else 0,
                               step_halvings=3 if refine else 0, frame_costs={"left_elbow_link": (20.0, 0.0)}))
    conf, limit = ik.configuration, ik.collision_limit
    if not resolve:
        limit.missed_pairs = lambda configuration: np.zeros(len(limit.pairs), dtype=bool)
    q = conf.q.copy()
    q[7 + g1.JOINT_INDEX["left_shoulder_roll_joint"]] = 0.6  # arm out to the side
    conf.update(q)
    elbow = [k for k in range(len(limit.pairs)) if "left_elbow_link_0" in limit.pair_names(k)
             and "torso_link_0" in limit.pair_names(k)]
    assert limit.distances(conf)[elbow].min() > limit.activation_m
    chest = conf.frame_placement(conf.frame_id("torso_link")).act(np.array([0.0, 0.0, 0.12]))
    ref = KinematicReference(root_pos_w_m=q[:3].copy(), root_quat_wxyz=np.array([q[6], *q[3:6]]),
                             q_rad=q[7:].copy(), frame_targets_w={"left_elbow_link": np.r_[chest, 1.0, 0.0, 0.0, 0.0]},
                             contacts=np.zeros(2, dtype=bool))
    q_new = ik.step(ref, q)
    assert np.linalg.norm(q_new[7:] - q[7:]) > 0.3  # a large step was taken
    assert not limit.include.any()  # the re-solve's extra rows are not kept for the next step
    return -limit.distances(conf).min()


def test_self_collision_holds_when_one_step_carries_an_elbow_from_beyond_the_activation_distance():
    assert _elbow_into_chest(resolve=False) > 0.02  # without the re-solve the arm ends inside the chest
    # with it: the margin, up to the linearisation error of a 1 rad step...
    assert _elbow_into_chest(resolve=True) < 0.012
    # ... which the trust-region re-solve and the projection step take out
    assert _elbow_into_chest(resolve=True, refine=True) < 0.002


def test_touchdown_lays_the_foot_along_a_ramp_and_holds_no_foot_out_of_reach():
    """The anchor of a touching-down foot is flat on the slope under it; a foot further than
    touchdown_reach_m above any support is not held at all."""
    from g1_control.ik.configuration import foot_contact_points
    from g1_control.motion.objects import ObjectShape, support_height

    probe = IKRetargeter()
    foot = probe.configuration.frame_placement(probe.configuration.frame_id("left_ankle_roll_link")).translation
    tilt = pin.utils.rpyToMatrix(0.2, 0.0, 0.0)  # a ramp rising toward -y (roll 0.2 rad), under the left foot
    ramp = ObjectShape.box("ramp", (0.3, 0.3, 0.05)).transformed(tilt, np.array([foot[0], foot[1], -0.04]))
    ik = IKRetargeter(IKConfig(scene=(ramp,), ground_snap_m=0.05))
    anchor = ik._touchdown_anchor("left_ankle_roll_link")
    normal = ramp.top_normal(np.array([foot[:2]]))[0]
    np.testing.assert_allclose(anchor.rotation[:, 2], normal, atol=1e-9)  # sole along the slope
    spheres = np.array([anchor.rotation @ c + anchor.translation - [0, 0, r]
                        for c, r in foot_contact_points()["left_ankle_roll_link"]])
    gaps = spheres[:, 2] - support_height((ramp,), spheres, 0.0, 0.05)
    assert gaps.min() > -2e-3 and gaps.max() < 0.02  # every sphere on (or just over) the slope

    high = IKRetargeter(IKConfig(touchdown_reach_m=0.05))
    q = high.configuration.q.copy()
    q[2] += 0.2  # the whole robot 20 cm up: no foot can stand anywhere
    high.reset(q)
    assert high._touchdown_anchor("left_ankle_roll_link") is None
    out = high.solve(_reference(high), q)
    assert out.contacts.tolist() == [False, False]


def test_a_tick_without_a_solution_leaves_the_configuration_where_the_tick_started():
    """The loop holds the last good reference when the IK fails (loop/control_loop.py): the next tick
    must start from this tick's start, not from the steps taken before the failing one."""
    ik = IKRetargeter(IKConfig(iterations=3, frame_costs={"left_rubber_hand": (50.0, 0.0)}))
    q = np.asarray(g1.DEFAULT_Q_RAD).copy()
    ik.solve(_reference(ik), q)
    q_start = ik.configuration.q.copy()
    q_start[7:] = q
    solve, calls = ik.solver.solve, [0]

    def first_step_only(*args, **kwargs):  # the first QP of the tick solves, every later one is infeasible
        calls[0] += 1
        if calls[0] > 1:
            raise NoSolutionFound("daqp found no IK step (exit flag -1: infeasible constraints)")
        return solve(*args, **kwargs)

    ik.solver.solve = first_step_only
    with pytest.raises(NoSolutionFound):
        ik.solve(_reference(ik, hand_offset=(0.1, 0.0, 0.1)), q)
    assert calls[0] > 2  # a step was taken, then the relaxed retries failed as well
    np.testing.assert_array_equal(ik.configuration.q, q_start)
    ik.solver.solve = solve
    out = ik.solve(_reference(ik), q)  # and the next tick solves from there
    assert np.all(np.isfinite(out.q_rad))
