"""A clip of the G1 standing still with its soles on the floor, for the clip checker's tests
(test_retarget_metrics.py, tests/cli/test_cli_check_cmd.py)."""

from __future__ import annotations

import numpy as np

from g1_control.motion.clip import MotionClip
from g1_control.robot import collision, description, g1


def sole_lift(q: np.ndarray) -> float:
    """Pelvis height that puts the lowest foot sphere of pose q exactly on the floor."""
    model = collision.collision_model()
    model.set_configuration(description.pinocchio_q(np.zeros(3), np.array([1.0, 0, 0, 0]), q))
    return -model.lowest_points().min()


def standing_clip(t: int, fps: float = 30.0, contacts: np.ndarray | None = None) -> MotionClip:
    """`t` frames of the default pose, pelvis at sole_lift, facing +x; `contacts` as given."""
    q = np.tile(np.asarray(g1.DEFAULT_Q_RAD), (t, 1))
    root = np.tile([0.0, 0.0, sole_lift(q[0])], (t, 1))
    quat = np.tile([1.0, 0.0, 0.0, 0.0], (t, 1))
    return MotionClip.from_joint_trajectory(fps, root, quat, q, contacts=contacts, source="stand")
