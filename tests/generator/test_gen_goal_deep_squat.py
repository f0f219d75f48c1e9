"""The deep squat stance (generator/goals/stances.py DEEP): a light box on the floor, below the reach
of the squats (pelvis >= 0.51 m), is held from a deep squat that passes the search's feasibility check
(hands on the grasp points, CoM over the feet, soles flat, leg joints inside their limits, pelvis above
the fall monitor's 0.40 m, static joint torques within the actuators' limits), and a short lockstep pick in MuJoCo (walking policy + whole-body controller,
as in g1 bench objects) lifts it from there. A heavier box, which the waist pitch's 35 N m cannot hold
out there, is refused naming the joint, with the closest pose."""

import numpy as np
import pytest

from g1_control.generator.goals.box import hand_points
from g1_control.generator.goals.poses import PosePlanner
from g1_control.generator.goals.stances import (
    DEEP,
    DEEP_MAX_TILT_RAD,
    DEEP_MIN_PELVIS_M,
    DEEP_TORQUE_SHARE,
    MIN_PELVIS_M,
    StancePlanner,
    StanceRefused,
    hand_height,
)
from g1_control.robot import g1
from g1_control.robot.dynamics import HAND_FRAMES, SOLE_FRAMES
from g1_control.scene import Box, SceneConfig

SIDE_M = 0.35
CENTER = np.array([1.2, 0.0, SIDE_M / 2])


def _box(mass_kg: float, side_m: float = SIDE_M) -> Box:
    return Box("box", (1.2, 0.0), size_m=(side_m, side_m, side_m), mass_kg=mass_kg)


@pytest.fixture(scope="module")
def stances():
    return StancePlanner(PosePlanner())


def test_a_light_floor_box_is_held_from_a_deep_squat_that_passes_the_checks(stances):
    box = _box(0.5)
    plan = stances.plan(box, CENTER, None, [0.0], lift_m=0.1, what="pick it up")
    assert plan.lean >= DEEP and "deep squat" in plan.chosen.describe()
    c = CENTER + np.array([0.0, 0.0, hand_height(box, CENTER[2])])
    assert c[2] < 0.30  # hands at a floor box's height: below anything the squats reach (~0.45 m)
    contact, lifted = plan.chosen.poses
    _, soles = stances.stance(plan.chosen.mid_xy, plan.chosen.heading, 0.0)
    for q, dz in ((contact, 0.0), (lifted, 0.1)):
        targets = hand_points(c, 0.0, plan.width_m, -0.01, dz_m=dz)
        err = max(float(np.linalg.norm(stances.ik.frame_pose(q, HAND_FRAMES[i])[0] - targets[i])) for i in range(2))
        assert err <= 0.02
        assert DEEP_MIN_PELVIS_M <= q[2] < MIN_PELVIS_M  # deeper than a squat, above the fall monitor's 0.40 m
        tilt = float(np.arccos(np.clip(stances.ik.frame_pose(q, "pelvis")[1][2, 2], -1.0, 1.0)))
        assert tilt <= DEEP_MAX_TILT_RAD  # below the safety layer's 1.0 rad
        assert stances.collision(q, box, CENTER, None) is None
        for (p, rot), frame in zip(soles, SOLE_FRAMES, strict=True):  # feet flat where they stand, heels down
            at, r = stances.ik.frame_pose(q, frame)
            assert np.linalg.norm(at - p) < 0.005 and np.abs(r - rot).max() < 0.03
        legs = q[7:19]
        assert np.all(legs > g1.Q_MIN_RAD[:12] + 0.05) and np.all(legs < g1.Q_MAX_RAD[:12] - 0.05)
        tau = stances.static_torques(q, soles, box.mass_kg if dz else 0.0)
        assert np.all(np.abs(tau) <= DEEP_TORQUE_SHARE * g1.EFFORT_LIMIT_NM)


def test_static_torques_balance_the_weight_and_see_the_box(stances):
    """The ground's reaction balances gravity and the box (the floating base's rows vanish), and a box
    at the hands loads the waist pitch more (the joint a deep squat runs out of first)."""
    box = _box(0.5)
    plan = stances.plan(box, CENTER, None, [0.0], lift_m=0.1, what="pick it up")
    _, soles = stances.stance(plan.chosen.mid_xy, plan.chosen.heading, 0.0)
    q = plan.chosen.poses[1]
    waist = g1.JOINT_INDEX["waist_pitch_joint"]
    empty, loaded = stances.static_torques(q, soles, 0.0), stances.static_torques(q, soles, 3.0)
    assert abs(loaded[waist]) > abs(empty[waist]) + 5.0
    assert "waist_pitch_joint needs" in (stances.torque_fault(q, soles, 3.0) or "")


def test_the_deep_squat_refuses_a_pose_that_lifts_a_heel(stances):
    q, soles = stances.stance(CENTER[:2] - np.array([0.4, 0.0]), 0.0, 0.0)
    assert stances.deep_fault(q, soles) is None
    q[7 + g1.JOINT_INDEX["left_ankle_pitch_joint"]] += 0.1  # the left foot tips about the ankle
    assert "left sole" in (stances.deep_fault(q, soles) or "")


def test_a_heavier_floor_box_is_refused_naming_the_joint_with_the_closest_deep_squat(stances):
    with pytest.raises(StanceRefused, match=r"1\.5 kg.*no stance can pick it up \(\d+ tried, pelvis down to 0\.47 m\): "
                                            r"waist_pitch_joint needs 3\d N m to hold still \(its limit 35 N m\); "
                                            r"closest: .*deep squat \(pelvis pitched .*\): hands \d\.\d cm off"):
        stances.plan(_box(1.5), CENTER, None, [0.0], lift_m=0.1, what="pick it up")


def lockstep_pick(mass_kg: float, side_m: float = SIDE_M) -> dict:
    """A pick of the floor cube (_box(mass_kg, side_m)) in lockstep MuJoCo, as g1 bench objects runs a
    trial; ground truth out. To measure the deep squat's mass limit (DEEP_MAX_KG) with the gate lifted:
    python3 -c "import g1_control.generator.goals.stances as s; s.DEEP_MAX_KG = 9;
    from tests.generator.test_gen_goal_deep_squat import lockstep_pick as p; print(p(1.5))" """
    from g1_control.launch.builder import build_loop
    from g1_control.report.outcomes import GoalWatcher
    from g1_control.teleop.scripted import GoalEntry, Segment
    from g1_control.tools.physics_trials import Trial, trial_launch

    timeline = [Segment(1.0, label="stand"), Segment(24.0, label="pick", goals=[GoalEntry("pick", object="box")])]
    trial = Trial("deep squat pick", timeline, tracker="layer", tracker_hz=100.0,
                  scene=SceneConfig(tables=[], boxes=[_box(mass_kg, side_m)]))
    loop = build_loop(trial_launch(trial))
    loop.reset()
    watcher = GoalWatcher(loop)
    gen = loop.generator
    pelvis: list[float] = []
    try:
        while loop.time_s < 25.0 and not gen.goal_status and not loop.fell:
            loop.run(0.5, progress=watcher.tick)
            pelvis.append(float(loop.backend.data.qpos[2]))  # type: ignore[attr-defined]
    finally:
        loop.backend.close()
    a = watcher.arrays()
    rise = a["box_box"][:, 2] - a["box_box"][0, 2]
    return {"fall": None if loop.fall is None else str(loop.fall), "status": dict(gen.goal_status),
            "messages": dict(gen.goal_messages), "log": [text for _, text in gen.goal_log],
            "pelvis_min_m": min(pelvis), "rise_max_m": float(rise.max()), "rise_end_m": float(rise[-1]),
            "box_to_hands_end_m": float(np.linalg.norm(a["box_box"][-1, :3] - a["hands_w_m"][-1].mean(axis=0)))}


def test_a_lockstep_pick_lifts_a_floor_box_from_the_deep_squat():
    r = lockstep_pick(0.5)
    assert r["fall"] is None, r["fall"]
    assert r["status"] == {"seg1.0": "reached"}, r["messages"]
    assert any("deep squat" in text for text in r["log"])
    # ground truth: it went down below any squat's pelvis, and the box came up with the hands
    assert r["pelvis_min_m"] < MIN_PELVIS_M
    assert r["rise_end_m"] > 0.3, f"box {r['rise_end_m'] * 100:.0f} cm up at the end (max {r['rise_max_m'] * 100:.0f} cm)"
    assert r["box_to_hands_end_m"] < 0.1


def test_a_place_below_the_squats_reach_is_planned_from_a_deep_squat(stances):
    """A place whose hands are below every squat's reach (LOWEST_GRASP_M) sets the box down from a deep
    squat (a carry into one fell until stepping.LEVEL_CHANGE_M; then DEEP_PICKS_ONLY refused it)."""
    plan = stances.plan(_box(0.5), CENTER, None, [0.0], lift_m=None, what="set it down there")
    assert plan.lean >= DEEP and "deep squat" in plan.chosen.describe()
    assert DEEP_MIN_PELVIS_M <= plan.chosen.poses[0][2] < MIN_PELVIS_M
