import numpy as np

from g1_control.motion.clip import MotionClip
from g1_control.retarget.metrics import compute_metrics, format_table, plot_metrics
from g1_control.robot import g1


def standing(t=30, height=None, fps=30.0) -> MotionClip:
    root = np.tile([0.0, 0.0, 0.0], (t, 1))
    quat = np.tile([1.0, 0.0, 0.0, 0.0], (t, 1))
    q = np.tile(np.asarray(g1.DEFAULT_Q_RAD), (t, 1))
    clip = MotionClip.from_joint_trajectory(fps, root, quat, q, contacts=np.ones((t, 2), bool), source="stand")
    # put the soles exactly on the ground: lowest sphere bottom at z = 0
    from g1_control.retarget.metrics import foot_series

    lift = -foot_series(clip).lowest_height_m.min() + (height or 0.0)
    return MotionClip.from_joint_trajectory(fps, root + [0, 0, lift], quat, q, contacts=np.ones((t, 2), bool),
                                            source="stand")


def test_clean_standing_clip_has_no_violations():
    m = compute_metrics(standing())
    assert m.passes()
    assert m.joint_limit_violations == m.velocity_limit_violations == m.penetration_frames == m.sliding_frames == 0
    assert m.max_penetration_m < 1e-9 and m.stance_frames == 29


def test_each_violation_is_counted():
    clip = standing(height=-0.02)  # 2 cm into the floor
    m = compute_metrics(clip)
    assert m.penetration_frames == 30 and m.max_penetration_m > 0.0199 and not m.passes()
    clip = standing()
    clip.joint_pos_rad[:, 4] = g1.Q_MAX_RAD[4] - 0.005  # ankle pitch resting near its upper limit
    clip.joint_pos_rad[5, 4] = g1.Q_MAX_RAD[4] + 0.005  # and 5 mrad past it on one frame
    m = compute_metrics(clip)
    assert m.joint_limit_violations == 1
    assert m.velocity_limit_violations == 0  # 0.3 rad/s is far below the 37 rad/s limit
    clip.joint_pos_rad[10, 0] += 2.0  # a 2 rad jump of the hip pitch in one frame: 60 rad/s, there and back
    assert compute_metrics(clip).velocity_limit_violations == 2


def test_sliding_counts_stance_frames_only():
    clip = standing()
    moving = clip.copy()
    moving.body_pos_w_m[15:, 6, 0] += 0.02  # left foot jumps 2 cm while in stance
    m = compute_metrics(moving)
    assert m.sliding_frames == 1 and m.max_sliding_m_per_frame > 0.019
    moving.contacts[14:16, 0] = False
    assert compute_metrics(moving).sliding_frames == 0


def test_table_and_plot(tmp_path):
    m = compute_metrics(standing())
    table = format_table([m, m])
    assert table.splitlines()[0].split()[:3] == ["clip", "frames", "jlim"] and len(table.splitlines()) == 4
    png = plot_metrics(standing(), tmp_path / "stand.png", m)
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
