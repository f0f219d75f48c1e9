"""Use the whole-body IK alone: move the right hand 15 cm up while both feet stay planted.

    python examples/ik_alone.py
"""

import numpy as np
import pinocchio as pin

import g1_control as g1c
from g1_control.robot import description

ik = g1c.IKRetargeter(g1c.IKConfig(iterations=2))
model = description.pinocchio_model()
data = model.createData()
hand = "right_rubber_hand"

q = description.pinocchio_q(np.array([0.0, 0.0, 0.79]), np.array([1.0, 0.0, 0.0, 0.0]), np.asarray(g1c.g1.DEFAULT_Q_RAD))
pin.framesForwardKinematics(model, data, q)
start = data.oMf[model.getFrameId(hand)].translation.copy()
goal = start + np.array([0.0, 0.0, 0.15])
feet = {f: data.oMf[model.getFrameId(f)].translation.copy() for f in g1c.g1.FOOT_BODIES}

q_joints = np.asarray(g1c.g1.DEFAULT_Q_RAD)
for k in range(100):  # 2 s at the loop's 50 Hz
    target = start + (goal - start) * min(1.0, k / 50)
    reference = g1c.KinematicReference(
        t_s=k * 0.02, root_pos_w_m=np.array([0.0, 0.0, 0.79]), q_rad=np.asarray(g1c.g1.DEFAULT_Q_RAD),
        frame_targets_w={hand: np.concatenate([target, [1.0, 0.0, 0.0, 0.0]])},
    )
    solution = ik.solve(reference, q_joints)
    q_joints = solution.q_rad

q = description.pinocchio_q(solution.root_pos_w_m, solution.root_quat_wxyz, solution.q_rad)
pin.framesForwardKinematics(model, data, q)
hand_err = np.linalg.norm(data.oMf[model.getFrameId(hand)].translation - goal)
foot_drift = max(np.linalg.norm(data.oMf[model.getFrameId(f)].translation - p) for f, p in feet.items())
print(f"hand {1000 * hand_err:.1f} mm from the goal 15 cm up; feet moved at most {1000 * foot_drift:.1f} mm")
assert hand_err < 0.03 and foot_drift < 0.005
