import numpy as np
import pinocchio as pin
from test_ik_frame_task import random_configuration

from g1_control.ik.configuration import Configuration, foot_contact_points
from g1_control.ik.limits import GroundLimit
from g1_control.motion.objects import ObjectShape
from g1_control.robot import g1


def test_foot_spheres_come_from_the_urdf():
    points = foot_contact_points()
    assert set(points) == set(g1.FOOT_BODIES)
    assert all(len(v) == 4 for v in points.values())
    # sole 3.5 cm below the ankle-roll frame: sphere centres at -3 cm, radius 5 mm (URDF)
    centres = np.array([c for c, _ in points["left_ankle_roll_link"]])
    np.testing.assert_allclose(centres[:, 2], -0.03)


def test_rows_lower_bound_is_minus_the_height_of_each_sphere_bottom():
    conf = Configuration()
    limit = GroundLimit(ground_height_m=0.01, tolerance_m=1e-4)
    rows = limit.compute(conf, 0.02)
    np.testing.assert_allclose(rows.lower, -limit.point_heights(conf) - 1e-4, atol=1e-12)


def test_rows_are_the_jacobian_of_the_point_heights():
    conf = random_configuration(12)
    limit = GroundLimit()
    rows = limit.compute(conf, 0.02).matrix.copy()
    q0 = conf.q.copy()
    eps = 1e-6
    fd = np.zeros_like(rows)
    for i in range(conf.nv):
        step = np.zeros(conf.nv)
        step[i] = eps
        conf.update(pin.integrate(conf.model, q0, step))
        plus = limit.point_heights(conf)
        conf.update(pin.integrate(conf.model, q0, -step))
        fd[:, i] = (plus - limit.point_heights(conf)) / (2 * eps)
    np.testing.assert_allclose(rows, fd, atol=2e-6)


def _box_near_left_foot(conf: Configuration, gap_m: float) -> ObjectShape:
    """A 20 cm box on the floor whose -x face is gap_m in front of the left foot's toe spheres."""

    placement = conf.frame_placement(conf.frame_id("left_ankle_roll_link"))
    toes = max(c[0] for c, _ in foot_contact_points()["left_ankle_roll_link"])
    radius = max(r for _, r in foot_contact_points()["left_ankle_roll_link"])
    face_x = placement.translation[0] + toes + radius + gap_m
    box = ObjectShape.box("step", (0.1, 0.3, 0.1))
    return box.transformed(np.eye(3), np.array([face_x + 0.1, placement.translation[1], 0.1]))


def test_scene_rows_are_the_jacobian_of_the_clearance_to_the_nearest_face():
    conf = random_configuration(5)
    from g1_control.motion.objects import ObjectShape

    # a box around the left foot's current position, so some spheres are near its faces
    foot = conf.frame_placement(conf.frame_id("left_ankle_roll_link")).translation
    box = ObjectShape.box("b", (0.06, 0.2, 0.05)).transformed(np.eye(3), foot + [0.12, 0.0, -0.04])
    limit = GroundLimit(ground_height_m=-10.0, scene=(box,), reach_m=1.0)  # floor far below: scene rows only
    clear0 = limit.scene_clearances(conf)[:, 0]
    rows = limit._scene_rows(conf)
    assert rows.matrix.shape == (len(limit.points), conf.nv)
    np.testing.assert_allclose(rows.lower, -clear0 - limit.tolerance_m, atol=1e-12)
    q0 = conf.q.copy()
    eps = 1e-6
    fd = np.zeros_like(rows.matrix)
    for i in range(conf.nv):
        step = np.zeros(conf.nv)
        step[i] = eps
        conf.update(pin.integrate(conf.model, q0, step))
        plus = limit.scene_clearances(conf)[:, 0]
        conf.update(pin.integrate(conf.model, q0, -step))
        fd[:, i] = (plus - limit.scene_clearances(conf)[:, 0]) / (2 * eps)
    np.testing.assert_allclose(rows.matrix, fd, atol=2e-6)


def test_a_foot_pushed_into_a_box_stops_at_its_face():
    from g1_control.ik.retargeter import IKConfig, IKRetargeter
    from g1_control.types import KinematicReference

    free = IKRetargeter(IKConfig(hold_contacts=False, frame_costs={"left_ankle_roll_link": (50.0, 1.0)}))
    box = _box_near_left_foot(free.configuration, gap_m=0.02)
    results = {}
    for name, scene in (("without", ()), ("with", (box,))):
        ik = IKRetargeter(IKConfig(hold_contacts=False, frame_costs={"left_ankle_roll_link": (50.0, 1.0)},
                                   scene=scene))
        foot = pin.SE3(ik.configuration.frame_placement(ik.configuration.frame_id("left_ankle_roll_link")))
        foot.translation = foot.translation + [0.10, 0.0, 0.0]  # 8 cm into the box
        quat = pin.Quaternion(foot.rotation)
        ref = KinematicReference(root_pos_w_m=np.array([0.0, 0.0, g1.DEFAULT_PELVIS_HEIGHT_M]),
                                 q_rad=np.asarray(g1.DEFAULT_Q_RAD).copy(), contacts=np.array([False, False]),
                                 frame_targets_w={"left_ankle_roll_link": np.r_[foot.translation, quat.w, quat.x,
                                                                                 quat.y, quat.z]})
        q = np.asarray(g1.DEFAULT_Q_RAD).copy()
        for _ in range(40):
            q = ik.solve(ref, q).q_rad
        results[name] = GroundLimit(scene=(box,)).scene_clearances(ik.configuration).min()
    assert results["without"] < -0.03, "the target is inside the box: without the scene the foot goes in"
    assert results["with"] > -1e-3
