"""Repairing a library piece that fails `g1 check` through the project's IK (ik/retargeter.py).

The piece's own motion is the reference (root pose, joint posture, hands, feet, elbows, knees,
torso), and the IK's limits do the repair: every pair of non-adjacent links kept apart (the URDF's
collision meshes), the feet held where the piece's contact labels put them (no sliding) and never
below the ground or the scene, free feet near the ground lifted clear, joint position and velocity
limits. The builder admits the result only if it then passes `g1 check` itself (builder.py).
"""

from __future__ import annotations

import numpy as np

from g1_control.motion.clip import MotionClip
from g1_control.robot import g1

REPAIR_TAG = "ik_repaired"

_TARGETS = (*g1.HAND_BODIES, *g1.FOOT_BODIES, "left_elbow_link", "right_elbow_link", "left_knee_link",
            "right_knee_link", g1.TORSO_BODY)
"""The piece's bodies the IK follows (hands, feet, elbows, knees: position; torso: orientation)."""


def repair_piece(clip: MotionClip) -> tuple[MotionClip, dict]:
    """(the piece through the IK, how far it moved: joint deviation mean/max in rad and the joint
    of the max). The clip keeps its fps, style and source and gains the REPAIR_TAG."""
    from g1_control.ik.retargeter import IKConfig, IKRetargeter
    from g1_control.motion.kinematics import default_body_names
    from g1_control.robot import description
    from g1_control.types import KinematicReference

    costs = {**{b: (8.0, 0.5) for b in g1.HAND_BODIES}, **{b: (10.0, 2.0) for b in g1.FOOT_BODIES},
             **{b: (2.0, 0.0) for b in _TARGETS[4:8]}, g1.TORSO_BODY: (0.0, 2.0)}
    ik = IKRetargeter(IKConfig(dt_s=1.0 / clip.fps, iterations=2, root_cost=(10.0, 5.0), frame_costs=costs,
                               com_cost=(0.0, 0.0, 0.0), posture_cost=0.3, smoothness_cost=0.1, self_collision=True,
                               swing_feet=True, scene=tuple(clip.scene)))
    idx = [clip.body_names.index(b) for b in _TARGETS]
    quat0 = clip.root_quat_wxyz[0] / np.linalg.norm(clip.root_quat_wxyz[0])
    q = description.pinocchio_q(clip.root_pos_w_m[0], quat0, clip.joint_pos_rad[0])
    ik.reset(q)
    qs = np.empty((clip.num_frames, q.shape[0]))
    for k in range(clip.num_frames):
        targets = {b: np.concatenate([clip.body_pos_w_m[k, i], clip.body_quat_wxyz[k, i]]) for b, i in zip(_TARGETS, idx)}
        reference = KinematicReference(t_s=k / clip.fps, root_pos_w_m=clip.root_pos_w_m[k],
                                       root_quat_wxyz=clip.root_quat_wxyz[k], q_rad=clip.joint_pos_rad[k],
                                       frame_targets_w=targets, contacts=np.asarray(clip.contacts[k], dtype=bool))
        q = ik.step(reference, q)
        qs[k] = q
    out = MotionClip.from_joint_trajectory(clip.fps, qs[:, :3], qs[:, [6, 3, 4, 5]], qs[:, 7:], source=clip.source,
                                           style=clip.style, tags=(*clip.tags, REPAIR_TAG),
                                           body_names=default_body_names(), object=clip.object, scene=tuple(clip.scene))
    deviation = np.abs(out.joint_pos_rad - clip.joint_pos_rad)
    worst = int(np.argmax(deviation.max(axis=0)))
    return out, {"joint_deviation_mean_rad": round(float(deviation.mean()), 4),
                 "joint_deviation_max_rad": round(float(deviation.max()), 3), "joint_deviation_max_at": g1.JOINT_NAMES[worst]}
