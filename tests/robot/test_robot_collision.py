"""The G1's collision geometry (robot/collision.py): what the clip checker measures and the IK keeps
apart are the same shapes."""

import numpy as np

from g1_control.ik.limits import SelfCollisionLimit
from g1_control.robot import collision, description, g1
from tests.ik.mesh_pair_checks import random_configurations


def test_geometries_come_from_the_urdf_and_pairs_skip_adjacent_links():
    model = collision.collision_model()
    assert len(model.geometries) == 36  # 28 meshes and cylinders, 8 foot spheres
    assert len(model.self_pairs) == 579
    names = {(model.geometries[a].link, model.geometries[b].link) for a, b in model.self_pairs}
    assert ("pelvis_contour_link", "torso_link") in names  # no geometry on the waist links between
    assert ("left_hip_pitch_link", "left_hip_roll_link") not in names  # one joint apart
    assert ("torso_link", "head_link") not in names  # fixed together: one link


def test_bounding_capsules_hold_their_geometry():
    for geom in collision.collision_model().geometries:
        p0, p1, radius = geom.capsule_j
        axis = p1 - p0
        t = np.clip((geom.points_j - p0) @ axis / max(axis @ axis, 1e-12), 0.0, 1.0)
        reach = np.linalg.norm(geom.points_j - (p0 + t[:, None] * axis), axis=1) + geom.radius_m
        assert (reach <= radius + 1e-9).all(), geom.name


def test_the_ik_uses_the_checkers_shapes(tmp_path):
    model = collision.collision_model()
    stand_ins = collision.ik_stand_ins()
    assert [s.name for s in stand_ins] == [g.name for g in model.geometries]
    pairs = collision.ik_self_pairs()
    index = {tuple(p): k for k, p in enumerate(model.self_pairs.tolist())}
    watched = [index[p] for p in pairs]
    limit = SelfCollisionLimit()
    assert [(a, b) for a, b, _ in limit.pairs] == pairs
    for conf in random_configurations(4, 3):
        model.set_configuration(conf.q)
        np.testing.assert_allclose(limit.distances(conf), model.self_distances(reach_m=np.inf)[watched], atol=1e-5)
    path = tmp_path / "c.npz"
    collision._save_stand_ins(stand_ins, pairs, path)
    back, back_pairs = collision._load_stand_ins(path)
    assert back_pairs == pairs
    for a, b in zip(stand_ins, back):
        assert (a.name, a.link, a.joint, a.kind, a.params) == (b.name, b.link, b.joint, b.kind, b.params)
        np.testing.assert_array_equal(a.points, b.points)
        np.testing.assert_array_equal(a.placement, b.placement)


def test_pairs_that_never_meet_are_the_ones_the_ik_leaves_out():
    model = collision.collision_model()
    watched = set(collision.ik_self_pairs())
    left_out = [tuple(p) for p in model.self_pairs.tolist() if tuple(p) not in watched]
    names = {(model.geometries[a].name, model.geometries[b].name) for a, b in left_out}
    assert 30 < len(left_out) < 80
    assert ("left_elbow_link_0", "left_wrist_pitch_link_0") in names  # 9.5 mm apart whatever the wrist does
    assert ("torso_link_0", "left_shoulder_roll_link_0") not in names  # the arm can swing into the chest
    # sampled: none of the left-out pairs comes within 5 mm over random configurations
    rng = np.random.default_rng(5)
    index = {tuple(p): k for k, p in enumerate(model.self_pairs.tolist())}
    for _ in range(200):
        q = description.pinocchio_q(np.zeros(3), np.array([1.0, 0, 0, 0]), rng.uniform(g1.Q_MIN_RAD, g1.Q_MAX_RAD))
        model.set_configuration(q)
        gaps = model.self_distances(reach_m=0.02)
        assert gaps[[index[p] for p in left_out]].min() > 0.005


def test_mujoco_spec_collides_every_collision_geometry():
    spec = collision.mujoco_collision_spec()
    colliding = [g for g in spec.geoms if g.contype and g.conaffinity]
    assert len(colliding) == 36 + 1  # the robot's and the floor
    model = spec.compile()
    assert model.ngeom > len(colliding)  # visual geometries stay out of collisions
    assert description.urdf_joint_limits()["velocity"].shape == (29,)
