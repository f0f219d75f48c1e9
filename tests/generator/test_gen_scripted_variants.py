"""Scripted whole-body references for a G1 variant: solved on that robot, so the joints it lacks
(the 23-DoF G1's waist roll/pitch and wrist pitch/yaw) stay at 0 and the others do the work."""

from __future__ import annotations

import numpy as np

from g1_control.generator.scripted import lean_reach
from g1_control.ik.whole_body import WholeBodyIK
from g1_control.robot import g1

DROPPED = ~g1.G1_23DOF.active_mask


def _joints(trajectory) -> np.ndarray:
    return np.array([trajectory.sample(t).q_rad for t in np.arange(0.0, trajectory.duration_s, 0.1)])


def test_the_23dof_reach_keeps_the_missing_joints_at_zero_and_still_reaches():
    full, base = _joints(lean_reach()), _joints(lean_reach(variant="g1_23dof"))
    assert np.abs(full[:, DROPPED]).max() > 0.05, "the 29-DoF reach leans with the waist"
    assert not base[:, DROPPED].any()
    ref = lean_reach(variant="g1_23dof")
    assert np.linalg.norm(ref.extras["hand_reference_w_m"] - ref.extras["hand_target_w_m"]) < 0.01


def test_the_ik_of_a_variant_never_moves_a_joint_it_lacks():
    ik = WholeBodyIK(g1.G1_23DOF)
    q0 = ik.nominal()
    soles = [ik.frame_pose(q0, name) for name in ("left_sole", "right_sole")]
    hand, _ = ik.frame_pose(q0, "left_hand")
    q = ik.solve(q0, soles, None, q0[2] - 0.1, np.eye(3), g1.DEFAULT_Q_RAD,
                 hands=[("left_hand", hand + [0.2, 0.1, 0.2])], iterations=40)
    assert not q[7:][DROPPED].any()
    assert abs(ik.frame_pose(q, "left_hand")[0][2] - (hand[2] + 0.2)) < 0.02
