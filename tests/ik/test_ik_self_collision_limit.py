"""SelfCollisionLimit (and the MeshPairLimit machinery it shares with SceneCollisionLimit): rows are
the derivative of coal's exact distance, the first cheap test never overestimates a gap, and the
limit keeps a link out of another one that the IK would otherwise drive into it."""

import numpy as np
import pinocchio as pin
import pytest

from g1_control.ik import kernels
from g1_control.ik.configuration import Configuration
from g1_control.ik.exceptions import LimitDefinitionError
from g1_control.ik.limits import SelfCollisionLimit
from g1_control.ik.retargeter import IKConfig, IKRetargeter
from g1_control.robot import g1
from g1_control.types import KinematicReference
from tests.ik.mesh_pair_checks import exact_distance_jacobian, random_configurations


def _arm_in() -> Configuration:
    conf = Configuration()
    q = conf.q.copy()
    q[7 + g1.JOINT_INDEX["left_shoulder_roll_joint"]] = -0.3  # swing the left arm in toward the body
    q[7 + g1.JOINT_INDEX["left_shoulder_yaw_joint"]] = 0.4
    conf.update(q)
    return conf


def test_joint_placements_kernel_is_pinocchio_forward_kinematics():
    limit = SelfCollisionLimit()
    rng = np.random.default_rng(0)
    for _ in range(5):
        q = pin.randomConfiguration(Configuration().model, -np.ones(36), np.ones(36))
        q[7:] = rng.uniform(g1.Q_MIN_RAD, g1.Q_MAX_RAD)
        conf = Configuration(q)
        limit.lower_bounds(conf)
        for j in range(1, conf.model.njoints):
            np.testing.assert_allclose(limit._joint_pos[j], conf.data.oMi[j].translation, atol=1e-12)
            np.testing.assert_allclose(limit._joint_rot[j], conf.data.oMi[j].rotation, atol=1e-12)


def test_capsule_bounds_never_exceed_the_exact_distance():
    limit = SelfCollisionLimit()
    for conf in random_configurations(1, 4):
        assert (limit.lower_bounds(conf) <= limit.distances(conf) + 1e-9).all()


def test_default_pose_is_clear_and_pairs_are_those_that_can_meet():
    limit = SelfCollisionLimit()
    assert 500 < len(limit.pairs) < 579  # of the 579 non-adjacent pairs, those that can meet
    assert limit.distances(Configuration()).min() > 0.009
    names = {tuple(sorted(limit.pair_names(k))) for k in range(len(limit.pairs))}
    assert ("left_hip_yaw_link_0", "torso_link_0") in names  # a raised thigh meets the chest
    assert ("left_hip_pitch_link_0", "pelvis_contour_link_0") not in names  # one joint apart: adjacent


def test_rows_are_the_jacobian_of_the_exact_distances():
    conf = _arm_in()
    limit = SelfCollisionLimit(activation_m=0.05)
    for request in limit.geometry_data.distanceRequests:  # tight GJK, as in the finite differences
        request.gjk_tolerance = request.epa_tolerance = 1e-10
    rows = limit.compute(conf, 0.02)
    active = np.flatnonzero(limit._rows)
    assert rows.matrix.shape[0] == active.size > 3
    dist = limit.exact(conf, active)[0]
    np.testing.assert_allclose(rows.lower, np.minimum(limit.margin_m - dist, limit.max_push_m), atol=1e-12)
    np.testing.assert_allclose(rows.matrix, exact_distance_jacobian(limit, conf, active), atol=2e-4)


def test_bad_setups_are_refused():
    with pytest.raises(LimitDefinitionError, match="margin_m < activation_m"):
        SelfCollisionLimit(margin_m=0.2, activation_m=0.1)


def test_missed_pairs_are_those_inside_the_margin_the_last_compute_gave_no_row():
    limit = SelfCollisionLimit()
    q = Configuration().q.copy()
    q[7 + g1.JOINT_INDEX["left_shoulder_roll_joint"]] = 0.8  # left arm well out to the side
    out = Configuration(q)
    limit.compute(out, 0.02)  # the QP of a step from `out`
    assert not limit.missed_pairs(out).any()
    q[7 + g1.JOINT_INDEX["left_shoulder_roll_joint"]] = -0.5  # where a large step took it: into the body
    q[7 + g1.JOINT_INDEX["left_elbow_joint"]] = 0.0
    inside = Configuration(q)
    missed = limit.missed_pairs(inside)
    assert missed.any() and (limit.exact(inside, np.flatnonzero(missed))[0] < limit.margin_m).all()
    k = int(np.flatnonzero(missed)[0])
    limit.include[k] = True  # `include` gives a pair a row whatever its distance...
    limit.compute(out, 0.02)
    assert limit._rows[k] and not limit.missed_pairs(inside)[k]  # ...and a pair with a row is never missed


def _hand_into_chest(self_collision: bool) -> float:
    """Drive the left hand into the chest with a heavy hand target; the deepest self-overlap."""
    ik = IKRetargeter(IKConfig(self_collision=self_collision, frame_costs={"left_rubber_hand": (50.0, 0.0)},
                               dt_s=1 / 30, iterations=2))
    conf = Configuration()
    torso = conf.frame_placement(conf.frame_id("torso_link"))
    hand = np.array([*torso.rotation @ [0.0, 0.0, 0.15] + torso.translation, 1.0, 0.0, 0.0, 0.0])
    ref = KinematicReference(t_s=0.0, root_pos_w_m=conf.q[:3].copy(), q_rad=np.asarray(g1.DEFAULT_Q_RAD).copy(),
                             frame_targets_w={"left_rubber_hand": hand}, contacts=np.array([True, True]))
    q = conf.q.copy()
    for _ in range(40):
        q = ik.step(ref, q)
    return -SelfCollisionLimit().distances(Configuration(q)).min()


def test_the_limit_keeps_the_hand_out_of_the_chest_and_without_it_the_hand_goes_in():
    assert _hand_into_chest(False) > 0.05
    assert _hand_into_chest(True) < 0.003


def test_kernels_warm_up_compiles_the_collision_kernels():
    kernels.warm_up()
    assert kernels.capsule_gaps.signatures and kernels.joint_placements.signatures
