"""SwingFootLimit: a free foot skimming the floor toward its next step lifts clear of it (or moves
slowly), so the clip checker sees no sliding; without the limit it slides."""

import numpy as np
import pytest

from g1_control.ik.configuration import Configuration
from g1_control.ik.exceptions import LimitDefinitionError
from g1_control.ik.limits import SwingFootLimit, SwingMode
from g1_control.ik.retargeter import IKConfig, IKRetargeter
from g1_control.motion.clip import MotionClip
from g1_control.retarget.metrics import compute_metrics
from g1_control.robot import g1
from g1_control.types import KinematicReference


def _skim(swing_feet: bool) -> MotionClip:
    """The left foot's target slides 24 cm forward along the floor in 12 frames (2 cm per frame, the
    foot free), the right foot held; both feet start on the floor."""
    ik = IKRetargeter(IKConfig(swing_feet=swing_feet, dt_s=1 / 30, iterations=2, com_cost=(0.0, 0.0, 0.0),
                               frame_costs={"left_ankle_roll_link": (20.0, 2.0)}))
    conf = Configuration()
    q = conf.q.copy()
    q[2] -= SwingFootLimit("left_ankle_roll_link").sole_height(conf)  # soles on the floor
    conf.update(q)
    foot = conf.frame_placement(conf.frame_id("left_ankle_roll_link"))
    frames = []
    for k in range(20):
        target = foot.translation + [0.02 * min(k, 12), 0.0, 0.0]
        ref = KinematicReference(t_s=k / 30, root_pos_w_m=q[:3] + [0.01 * min(k, 12), 0.0, 0.0],
                                 q_rad=np.asarray(g1.DEFAULT_Q_RAD).copy(), contacts=np.array([False, True]),
                                 frame_targets_w={"left_ankle_roll_link": np.array([*target, 1.0, 0.0, 0.0, 0.0])})
        q = ik.step(ref, q)
        frames.append(q.copy())
    qs = np.array(frames)
    return MotionClip.from_joint_trajectory(30.0, qs[:, :3], qs[:, [6, 3, 4, 5]], qs[:, 7:], source="skim")


def test_a_skimming_foot_slides_without_the_limit_and_not_with_it():
    assert compute_metrics(_skim(False)).sliding_frames >= 5
    assert compute_metrics(_skim(True)).sliding_frames == 0


def test_modes():
    conf = Configuration()
    limit = SwingFootLimit("left_ankle_roll_link", near_m=0.03, clearance_m=0.025, max_slide_m=0.009)
    supports = limit.bottoms_w(conf)[:, 2]  # each sphere resting on something
    origin = conf.frame_placement(conf.frame_id("left_ankle_roll_link")).translation
    assert limit.plan(conf, supports, origin[:2] + [0.05, 0.0]) is SwingMode.LIFT
    rows = limit.compute(conf, 1 / 30)
    np.testing.assert_allclose(rows.lower, 0.025, atol=1e-12)  # each sphere 2.5 cm up
    assert limit.plan(conf, supports, origin[:2] + [0.005, 0.0]) is SwingMode.SLOW
    rows = limit.compute(conf, 1 / 30)
    assert rows.matrix.shape[0] == 8 and np.allclose(rows.upper, 0.009 / np.sqrt(2))
    assert limit.plan(conf, supports - 0.05, origin[:2] + [0.05, 0.0]) is SwingMode.FREE  # 5 cm up: free
    assert limit.compute(conf, 1 / 30) is None
    with pytest.raises(LimitDefinitionError, match="clearance_m <= near_m"):
        SwingFootLimit("left_ankle_roll_link", near_m=0.01, clearance_m=0.02)
