"""Where the hands, the soles and the boxes really are over a run (MuJoCo's ground truth), for judging
goals against what they asked (report/outcomes.py judge_goal): in `g1 launch` (GoalWatcher, simulated
time) and in the robot emulator (`g1 sim-robot --record`, the host's monotonic clock, which the robot
path's states and goal records are stamped with too)."""

from __future__ import annotations

import numpy as np

from g1_control.robot import g1
from g1_control.robot.dynamics import HAND_OFFSET_M, SOLE_OFFSET_M
from g1_control.sim.mujoco_backend import MujocoBackend


class GroundTruthRecorder:
    """sample(t_s) records the hand points (wrist-yaw link + 0.1 m), the sole points and each box's and
    bottle's pose."""

    def __init__(self, sim: MujocoBackend):
        m = sim.model
        self.sim, self.data = sim, sim.data
        self.hands = [m.body(n).id for n in g1.HAND_BODIES]
        self.feet = [m.body(n).id for n in g1.FOOT_BODIES]
        self.objects = [(f"box_{b.name}", b.name) for b in sim.scene.boxes]
        self.objects += [(f"bottle_{b.name}", b.name) for b in sim.scene.bottles]
        """(key in arrays(), body name) of every free object the scene has."""
        self.t: list[float] = []
        self.hand_w: list[np.ndarray] = []
        self.sole_w: list[np.ndarray] = []
        self.object_w: dict[str, list[np.ndarray]] = {key: [] for key, _ in self.objects}

    def sample(self, t_s: float) -> None:
        d = self.data
        self.t.append(t_s)
        self.hand_w.append(np.array([d.xpos[b] + d.xmat[b].reshape(3, 3) @ HAND_OFFSET_M for b in self.hands]))
        self.sole_w.append(np.array([d.xpos[b] + d.xmat[b].reshape(3, 3) @ SOLE_OFFSET_M for b in self.feet]))
        for key, name in self.objects:
            pos, quat = self.sim.object_pose(name)
            self.object_w[key].append(np.concatenate([pos, quat]))

    def arrays(self) -> dict[str, np.ndarray]:
        """t_s, hands_w_m (n, 2, 3), soles_w_m (n, 2, 3), box_<name> and bottle_<name> (n, 7: position,
        quaternion wxyz)."""
        out = {"t_s": np.array(self.t), "hands_w_m": np.array(self.hand_w).reshape(-1, 2, 3),
               "soles_w_m": np.array(self.sole_w).reshape(-1, 2, 3)}
        for key, rows in self.object_w.items():
            out[key] = np.array(rows).reshape(-1, 7)
        return out


__all__ = ["GroundTruthRecorder"]
