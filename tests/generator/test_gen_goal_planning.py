"""Goal planning without physics: reach poses and refusals, grasp poses, footstep plans (feet
alternate, turning, steps up and down the legs can take), the pelvis rules for levels."""

import itertools
import math

import numpy as np
import pytest

from g1_control.generator.goals.box import grasp_width, hand_forces, hand_points, pick_approach, place_target
from g1_control.generator.goals.poses import PosePlanner, ReachRefused, flat_soles
from g1_control.generator.goals.stepping import (
    LEFT,
    Stance,
    SteppingConfig,
    level_steps,
    stepping_trajectory,
    walk_steps,
)
from g1_control.robot import g1
from g1_control.scene import Box, SceneConfig, Table


@pytest.fixture(scope="module")
def planner():
    return PosePlanner()


def test_reach_puts_the_hand_on_the_point(planner):
    q0 = planner.ik.nominal()
    soles = flat_soles(planner.ik, q0)
    target = np.array([0.40, -0.20, 0.95])
    res = planner.reach(q0, soles, 1, target)
    assert res.residual_m < 0.01
    assert np.linalg.norm(planner.hand_point(res.q, 1) - target) < 0.01
    # feet where they were, joints within their limits
    for name, (p, _) in zip(("left_sole", "right_sole"), soles):
        assert np.linalg.norm(planner.ik.frame_pose(res.q, name)[0] - p) < 2e-3
    assert np.all(res.q[7:] >= g1.Q_MIN_RAD) and np.all(res.q[7:] <= g1.Q_MAX_RAD)


def test_a_point_out_of_reach_is_refused_with_the_distance(planner):
    q0 = planner.ik.nominal()
    with pytest.raises(ReachRefused, match=r"0\.\d\d m from the shoulder"):
        planner.reach(q0, flat_soles(planner.ik, q0), 0, np.array([0.9, 0.3, 1.0]))


def test_grasp_hands_on_a_box_ahead(planner):
    q0 = planner.ik.nominal()
    soles = flat_soles(planner.ik, q0)
    box = Box("box", (0.40, 0.0), size_m=(0.3, 0.3, 0.3))
    targets = hand_points(np.array([0.40, 0.0, 0.85]), 0.0, grasp_width(box, 0.0), -0.01)
    assert targets[0][1] - targets[1][1] == pytest.approx(0.3 + 2 * 0.045 - 0.02)
    res = planner.hands_on(q0, soles, targets, 0.0)
    assert res.residual_m < 0.01
    f = hand_forces(0.0, 20.0, 19.62)
    assert f[0] == pytest.approx([0.0, 20.0, -9.81]) and f[1] == pytest.approx([0.0, -20.0, -9.81])


def test_box_stances_face_the_table_edge_and_refuse_a_box_too_far_in():
    table = Table("t", (2.0, 0.0), (0.5, 0.8), 0.7)
    box = Box("box", (1.9, 0.1), stands_on="t")
    scene = SceneConfig(tables=[table], boxes=[box])
    a = pick_approach(scene, box, np.array([1.9, 0.1]), np.zeros(2))
    assert abs(a.heading) < 1e-9 and np.allclose(a.pelvis_xy(), [1.5, 0.1])
    far_side = pick_approach(scene, box, np.array([2.2, 0.0]), np.zeros(2))
    assert abs(abs(far_side.heading) - math.pi) < 1e-9  # nearer the far edge: picked from there
    with pytest.raises(ReachRefused, match="inside the edge"):
        pick_approach(scene, box, np.array([2.0, 0.0]), np.zeros(2))
    center, stance = place_target(scene, box, "t", None, np.array([0.0, 0.0]))
    assert np.allclose(center, [1.75 + 0.18, 0.0, 0.85]) and abs(stance.heading) < 1e-9


def test_walk_steps_turn_walk_and_keep_the_feet_alternating(planner):
    q0 = planner.ik.nominal()
    stance = Stance.of(planner.ik, q0)
    cfg = SteppingConfig(max_advance_m=0.12, max_turn_rad=0.18)
    steps = walk_steps(stance, np.array([0.0, 1.2]), math.pi / 2, cfg)
    feet = [s.foot for s in steps]
    assert all(a != b for a, b in itertools.pairwise(feet)), "a foot never steps twice in a row"
    end = stance
    for s in steps:
        end = end.apply(s)
    assert end.mid_xy == pytest.approx([0.0, 1.2], abs=0.01) and end.heading == pytest.approx(math.pi / 2, abs=0.01)
    # more: the continuation keeps alternating from a previous plan
    more = walk_steps(end, np.array([0.5, 1.2]), math.pi / 2, cfg, then=steps)
    assert more[0].foot != steps[-1].foot


def test_step_up_and_down_plans_keep_the_feet_on_target_and_the_knees_bent(planner):
    ik = planner.ik
    q0 = ik.nominal()
    cfg = SteppingConfig()
    up = level_steps(Stance.of(ik, q0), 0.26, 0.15, cfg, lead=LEFT)
    plan = stepping_trajectory(ik, q0, up, cfg)
    assert plan.sole_error_m < 0.02
    z, c = plan.pelvis_z_m, plan.trajectory.contacts
    # on top: the pelvis at its height above the platform; while the trailing foot swings up it
    # stays as low as the floor leg allows (rising then threw the body up, measured)
    assert z[-1] == pytest.approx(0.15 + cfg.pelvis_above_ground_m, abs=1e-3)
    trailing = np.flatnonzero(~c[:, 1])
    assert z[trailing].max() <= cfg.pelvis_above_ground_m + 0.031
    knees = [g1.JOINT_INDEX["left_knee_joint"], g1.JOINT_INDEX["right_knee_joint"]]
    assert plan.trajectory.q_rad[:, knees].min() > 0.2

    q_top = plan.trajectory.q_rad[-1]
    w, x, y, zq = __import__("g1_control.rotations", fromlist=["rpy_to_quat"]).rpy_to_quat(plan.trajectory.root_rpy_rad[-1])
    q1 = np.concatenate([plan.trajectory.root_pos_w_m[-1], [x, y, zq, w], q_top])
    down = level_steps(Stance.of(ik, q1), -0.26, 0.0, cfg)
    plan = stepping_trajectory(ik, q1, down, cfg)
    assert plan.sole_error_m < 0.02
    # the body lowers before the first foot reaches down, and ends standing on the floor
    first_swing = np.flatnonzero(~plan.trajectory.contacts.all(axis=1))[0]
    assert plan.pelvis_z_m[first_swing] < 0.15 + cfg.pelvis_above_ground_m - 0.05
    assert plan.pelvis_z_m[-1] == pytest.approx(cfg.pelvis_above_ground_m, abs=1e-3)
    assert plan.trajectory.q_rad[:, knees].min() > 0.2


@pytest.mark.parametrize("above_m", [1e-5, 5e-3])
def test_a_stance_a_hair_above_the_floor_steps_on_level(planner, above_m):
    """A whole-body pose's soles sit micrometres off the floor (IK residual: +7.5 um at the end of
    a carry). Steps from there onto the floor are level steps: no forward lean, no lowered pelvis
    (read as a step down, they leaned the pelvis 0.3 rad before the first correcting step after a
    carry, and the robot fell)."""
    ik = planner.ik
    q0 = ik.nominal()
    q0[2] += above_m
    cfg = SteppingConfig(max_advance_m=0.10, max_turn_rad=0.18, single_support_s=0.6, double_support_s=0.25)
    stance = Stance.of(ik, q0)
    steps = walk_steps(stance, stance.mid_xy + np.array([0.06, 0.0]), stance.heading, cfg)
    assert steps and all(s.pos_w_m[2] == 0.0 for s in steps)
    plan = stepping_trajectory(ik, q0, steps, cfg)
    assert plan.sole_error_m < 0.01
    assert np.abs(plan.trajectory.root_rpy_rad[:, 1]).max() < 0.02
    assert plan.pelvis_z_m.min() > cfg.pelvis_above_ground_m - 0.002
