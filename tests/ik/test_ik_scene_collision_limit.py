"""SceneCollisionLimit keeps every link (not only the feet) out of the floor and the scene's boxes:
each test drives a link into one with a heavy target, and checks that it goes in without the limit."""

import numpy as np
import pinocchio as pin

from g1_control.ik.configuration import Configuration
from g1_control.ik.limits import GroundLimit, SceneCollisionLimit
from g1_control.ik.retargeter import IKConfig, IKRetargeter
from g1_control.motion.objects import ObjectShape
from g1_control.robot import g1
from g1_control.types import KinematicReference
from tests.ik.mesh_pair_checks import exact_distance_jacobian


def _drive(frame: str, shift: np.ndarray, scene: tuple, scene_collision: bool, steps: int = 40,
           root_shift: np.ndarray | None = None) -> Configuration:
    ik = IKRetargeter(IKConfig(scene=scene, scene_collision=scene_collision, frame_costs={frame: (50.0, 0.0)},
                               dt_s=1 / 30, iterations=2))
    conf = Configuration()
    target = conf.frame_placement(conf.frame_id(frame)).translation + shift
    root = conf.q[:3] + (root_shift if root_shift is not None else 0.0)
    ref = KinematicReference(t_s=0.0, root_pos_w_m=root, q_rad=np.asarray(g1.DEFAULT_Q_RAD).copy(),
                             frame_targets_w={frame: np.array([*target, 1.0, 0.0, 0.0, 0.0])},
                             contacts=np.array([True, True]))
    q = conf.q.copy()
    for _ in range(steps):
        q = ik.step(ref, q)
    return Configuration(q)


def test_a_knee_driven_into_a_box_stops_at_it_and_goes_in_without_the_limit():
    conf = Configuration()
    knee = conf.frame_placement(conf.frame_id("left_knee_link")).translation
    # a box 3 cm in front of the knee, above the feet; the knee target is 10 cm into it
    box = ObjectShape.box("box", (0.1, 0.3, 0.1)).transformed(np.eye(3), knee + [0.13, 0.0, 0.05])
    inside = SceneCollisionLimit(scene=(box,), ground_height_m=None)
    free = _drive("left_knee_link", np.array([0.13, 0.0, 0.0]), (box,), scene_collision=False)
    kept = _drive("left_knee_link", np.array([0.13, 0.0, 0.0]), (box,), scene_collision=True)
    assert inside.distances(free).min() < -0.03
    assert inside.distances(kept).min() > -0.003


def test_a_body_pulled_through_the_floor_stops_at_it_and_goes_in_without_the_limit():
    from g1_control.ik.solver import QPSolver
    from g1_control.ik.tasks import FrameTask

    floor = SceneCollisionLimit(ground_height_m=0.0)
    conf = Configuration()
    q = conf.q.copy()
    q[2] -= floor.distances(conf).min() - 0.01  # the lowest link (not a foot) 1 cm above the floor
    conf.update(q)
    target = pin.SE3(conf.frame_placement(conf.frame_id("pelvis")))
    target.translation = target.translation - [0.0, 0.0, 0.06]  # pull the whole body 6 cm down
    pull = FrameTask("pelvis", 10.0, 10.0)
    pull.set_target(target)
    depth = {}
    for name, limits in (("without", []), ("with", [floor])):
        moved = Configuration(q)
        moved.integrate_inplace(QPSolver().solve(moved, [pull], limits, 1 / 30))
        depth[name] = floor.distances(moved).min()
    assert depth["without"] < -0.04 and depth["with"] > 0.0


def test_feet_are_left_to_the_ground_limit():
    limit = SceneCollisionLimit()
    links = {limit.stand_ins[a].link for a, _, _ in limit.pairs}
    assert not links & set(g1.FOOT_BODIES) and "left_knee_link" in links and "torso_link" in links


def test_the_ground_limit_catches_a_foot_swung_into_a_box_from_beyond_its_reach():
    conf = Configuration()
    foot = conf.frame_placement(conf.frame_id("left_ankle_roll_link")).translation
    box = ObjectShape.box("step", (0.1, 0.3, 0.1)).transformed(np.eye(3), np.array([foot[0] + 0.35, foot[1], 0.1]))
    limit = GroundLimit(scene=(box,), reach_m=0.05)
    limit.compute(conf, 1 / 30)  # the foot is 15 cm from the box: no scene rows
    assert not limit._scene_rowed.any() and not limit.missed_pairs(conf).any()
    q = conf.q.copy()
    q[0] += 0.3  # where a large step took the body: the left foot inside the box
    moved = Configuration(q)
    missed = limit.missed_pairs(moved)
    assert missed.any()
    limit.include |= missed
    rows = limit._scene_rows(conf)  # the step solved again from `conf` has rows for those spheres
    assert rows is not None and limit._scene_rowed[missed].all()


def test_scene_rows_are_the_jacobian_of_the_exact_distance_to_a_box():
    conf = Configuration()
    knee = conf.frame_placement(conf.frame_id("left_knee_link")).translation
    box = ObjectShape.box("box", (0.1, 0.3, 0.1)).transformed(np.eye(3), knee + [0.12, 0.0, 0.05])
    limit = SceneCollisionLimit(scene=(box,), ground_height_m=None, activation_m=0.05)
    for request in limit.geometry_data.distanceRequests:
        request.gjk_tolerance = request.epa_tolerance = 1e-10
    rows = limit.compute(conf, 1 / 30)
    active = np.flatnonzero(limit._rows)
    assert active.size >= 2
    np.testing.assert_allclose(rows.matrix, exact_distance_jacobian(limit, conf, active), atol=2e-4)
