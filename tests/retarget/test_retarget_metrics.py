"""Each clip metric against a hand-built case whose answer is known."""

import numpy as np
import pytest

from g1_control.motion.clip import MotionClip
from g1_control.motion.objects import ObjectShape
from g1_control.retarget.clip_geometry import measure, mujoco_cross_check
from g1_control.retarget.metrics import compute_metrics, format_table, plot_metrics
from g1_control.robot import collision, description, g1
from tests.retarget.standing_clips import standing_clip


def standing(t: int = 30, fps: float = 30.0) -> MotionClip:
    return standing_clip(t, fps, contacts=np.ones((t, 2), bool))


def test_clean_standing_clip_has_no_violations():
    m = compute_metrics(standing())
    assert m.passes()
    assert m.joint_limit_violations == m.velocity_limit_violations == m.penetration_frames == 0
    assert m.sliding_frames == m.self_collision_frames == 0
    assert m.max_penetration_m < 1e-9 and m.near_ground_frames == 29  # every frame but the first


def test_a_link_2cm_inside_a_box_is_2cm_deep():
    clip = standing()
    model = collision.collision_model()
    model.set_configuration(description.pinocchio_q(clip.root_pos_w_m[0], clip.root_quat_wxyz[0],
                                                    clip.joint_pos_rad[0]))
    rot, pos = model._joint_poses()
    fronts = [(g.points_j @ rot[k].T + pos[k])[:, 0].max() + g.radius_m for k, g in enumerate(model.geometries)]
    tip = max(fronts)  # the robot's front-most point, and the link it belongs to
    link = model.geometries[int(np.argmax(fronts))].link

    def wall(depth):  # a big box whose back face is `depth` behind that point
        return ObjectShape.box("wall", (0.2, 1.0, 1.0)).transformed(np.eye(3), np.array([tip - depth + 0.2, 0, 1.0]))

    m = compute_metrics(clip, scene=(wall(0.02),))
    assert m.max_penetration_m == pytest.approx(0.02, abs=2e-4)
    # the robot is symmetric: the left or the right one of that link
    assert m.penetration_frames == clip.num_frames and not m.passes()
    assert m.penetration_link.split("_", 1)[1] == link.split("_", 1)[1]
    assert compute_metrics(clip, scene=(wall(0.005),)).penetration_frames == 0  # within the 1 cm tolerance
    sunk = clip.copy()
    sunk.root_pos_w_m[:, 2] -= 0.02  # the whole robot 2 cm down: the feet 2 cm into the floor
    s = compute_metrics(sunk, scene=())
    assert s.max_penetration_m == pytest.approx(0.02, abs=1e-9) and s.penetration_link.endswith("ankle_roll_link")
    # MuJoCo's collision detection on the same meshes finds the same depth
    cross = mujoco_cross_check(clip, scene=(wall(0.02),))
    np.testing.assert_allclose(cross.penetration_m, 0.02, atol=5e-4)


def test_two_boxes_overlapping_by_2cm_are_2cm_deep():
    """The signed distance both metrics use (coal on convex shapes), and MuJoCo's, on two boxes."""
    import coal

    a = collision.convex_shape(ObjectShape.box("a", (0.1, 0.1, 0.1)).vertices())
    b_shape = ObjectShape.box("b", (0.1, 0.1, 0.1)).transformed(np.eye(3), np.array([0.18, 0.0, 0.0]))
    b = collision.convex_shape(b_shape.vertices())
    result = coal.DistanceResult()
    depth = coal.distance(a, coal.Transform3s(), b, coal.Transform3s(), coal.DistanceRequest(), result)
    assert depth == pytest.approx(-0.02, abs=1e-6)


def test_a_foot_dragged_3cm_on_the_floor_slides_and_lifted_it_does_not():
    clip = standing()
    foot = clip.joint_pos_rad.copy()
    dragged = MotionClip.from_joint_trajectory(clip.fps, clip.root_pos_w_m.copy(), clip.root_quat_wxyz, foot,
                                               source="drag")
    dragged.root_pos_w_m[15:, 0] += 0.03  # the whole robot (both feet on the floor) jumps 3 cm forward
    m = compute_metrics(dragged)
    assert m.sliding_frames == 1 and m.max_sliding_m_per_frame == pytest.approx(0.03, abs=1e-9)
    assert m.sliding_fraction == pytest.approx(1 / 29) and not m.passes()
    lifted = dragged.copy()
    lifted.root_pos_w_m[15:, 2] += 0.05  # ... while rising 5 cm: the feet leave the 2 cm band
    assert compute_metrics(lifted).sliding_frames == 0
    hover = dragged.copy()
    hover.root_pos_w_m[:, 2] += 0.025  # 2.5 cm up all along: never near the ground
    h = compute_metrics(hover)
    assert h.near_ground_frames == 0 and h.sliding_frames == 0


def test_stance_needs_slow_vertical_motion():
    clip = standing()
    bob = clip.copy()
    bob.root_pos_w_m[:, 2] += 0.015 * (np.arange(clip.num_frames) % 2)  # 1.5 cm up and down every frame
    geo = measure(bob)
    assert not geo.stance[1:].any()  # 0.45 m/s vertically: no stance though within 2 cm


def test_a_joint_at_31_radps_breaks_the_30_radps_ankle_limit():
    clip = standing()
    ankle = g1.JOINT_INDEX["left_ankle_pitch_joint"]
    assert description.urdf_joint_limits()["velocity"][ankle] == 30.0
    fast = clip.copy()
    fast.joint_pos_rad[10:, ankle] += 31.0 / clip.fps  # one frame at 31 rad/s
    m = compute_metrics(fast)
    assert m.velocity_limit_violations == 1 and m.max_velocity_ratio == pytest.approx(31 / 30)
    ok = clip.copy()
    ok.joint_pos_rad[10:, ankle] += 29.0 / clip.fps
    assert compute_metrics(ok).velocity_limit_violations == 0
    out = clip.copy()
    out.joint_pos_rad[5, ankle] = description.urdf_joint_limits()["upper"][ankle] + 0.005
    assert compute_metrics(out).joint_limit_violations == 1


def test_crossed_legs_are_a_self_collision_and_mujoco_agrees():
    q = np.tile(np.asarray(g1.DEFAULT_Q_RAD), (3, 1))
    roll_l, roll_r = g1.JOINT_INDEX["left_hip_roll_joint"], g1.JOINT_INDEX["right_hip_roll_joint"]
    q[1, roll_l], q[1, roll_r] = -0.5, 0.5  # both legs swung in: the knees and shins cross
    q[2, roll_l], q[2, roll_r] = -0.2, 0.2
    root = np.tile([0.0, 0.0, 0.8], (3, 1))
    clip = MotionClip.from_joint_trajectory(30.0, root, np.tile([1.0, 0, 0, 0], (3, 1)), q, source="cross")
    geo = measure(clip, scene=())
    assert geo.self_penetration_m[0] == 0.0 and geo.self_penetration_m[1] > 0.05
    assert {geo.links[i] for i in geo.self_pair[1]} <= {"left_hip_yaw_link", "right_hip_yaw_link", "left_knee_link",
                                                       "right_knee_link"}
    m = compute_metrics(clip, scene=(), geometry=geo)
    assert m.self_collision_frames >= 1 and "/" in m.self_collision_pair
    cross = mujoco_cross_check(clip, scene=())
    np.testing.assert_allclose(cross.self_penetration_m, geo.self_penetration_m, atol=5e-4)


def test_table_and_plot(tmp_path):
    m = compute_metrics(standing())
    table = format_table([m, m])
    assert table.splitlines()[0].split()[:3] == ["clip", "frames", "jlim"] and len(table.splitlines()) == 4
    png = plot_metrics(standing(), tmp_path / "stand.png", m)
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
