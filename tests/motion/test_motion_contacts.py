import numpy as np

from g1_control.motion.contacts import foot_contacts, stance_from_trajectory


def test_slow_low_feet_are_in_stance_and_swing_is_not():
    fps = 30.0
    t = np.arange(60) / fps
    x = np.where(t < 1.0, 0.0, np.minimum((t - 1.0) * 1.0, 0.3))  # rests, then moves at 1 m/s, rests
    z = np.where((t >= 1.0) & (t < 1.3), 0.1, 0.0)
    foot = np.stack([x, np.zeros_like(x), z], axis=1)
    stance = stance_from_trajectory(foot, fps, max_speed_mps=0.3)
    assert stance[:28].all() and not stance[31:39].any() and stance[-15:].all()


def test_short_stance_blips_are_dropped_and_height_gate_applies():
    fps = 30.0
    pos = np.zeros((20, 3))
    pos[:, 0] = np.arange(20) * 0.05  # 1.5 m/s
    pos[10, 0] = pos[9, 0]  # one frame of zero speed
    pos[11:, 0] -= 0.05
    assert not stance_from_trajectory(pos, fps, min_frames=3).any()
    feet = np.zeros((10, 2, 3))
    feet[:, 1, 2] = 0.3  # right foot resting on a 30 cm step
    labels = foot_contacts(feet, fps, max_height_m=0.08)
    assert labels[:, 0].all() and not labels[:, 1].any()
