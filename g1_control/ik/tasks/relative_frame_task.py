"""Hold one robot frame at a pose expressed in another robot frame (e.g. a hand relative to the
torso, or one foot relative to the other), whatever the floating base does.

Error: position R_r^T (p_f - p_r) - p* (m, in the root frame's axes), orientation
log(R*^T R_r^T R_f) (rad, in the frame's own axes).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from g1_control.ik.configuration import Configuration
from g1_control.ik.exceptions import TaskDefinitionError
from g1_control.ik.tasks.base import Task, check_cost


class RelativeFrameTask(Task):
    def __init__(self, frame: str, root: str, position_cost: float | np.ndarray = 1.0,
                 orientation_cost: float | np.ndarray = 1.0, gain: float = 1.0, lm_damping: float = 0.0) -> None:
        pos = check_cost(f"RelativeFrameTask('{frame}' in '{root}') position", position_cost, 3)
        ori = check_cost(f"RelativeFrameTask('{frame}' in '{root}') orientation", orientation_cost, 3)
        super().__init__(np.concatenate([np.broadcast_to(pos, 3), np.broadcast_to(ori, 3)]), gain, lm_damping)
        if frame == root:
            raise TaskDefinitionError(f"RelativeFrameTask needs two different frames. Got '{frame}' twice")
        self.frame, self.root = frame, root
        self.target: pin.SE3 | None = None

    def set_target(self, target_in_root: pin.SE3) -> None:
        self.target = target_in_root

    def set_target_from_configuration(self, configuration: Configuration) -> None:
        self.target = self._relative(configuration)

    def _relative(self, configuration: Configuration) -> pin.SE3:
        root = configuration.frame_placement(configuration.frame_id(self.root))
        frame = configuration.frame_placement(configuration.frame_id(self.frame))
        return root.actInv(frame)

    def _check_target(self) -> pin.SE3:
        if self.target is None:
            raise TaskDefinitionError(f"RelativeFrameTask('{self.frame}' in '{self.root}') has no target; "
                                      "call set_target first")
        return self.target

    def compute_error(self, configuration: Configuration) -> np.ndarray:
        target = self._check_target()
        rel = self._relative(configuration)
        return np.concatenate([rel.translation - target.translation,
                               pin.log3(target.rotation.T @ rel.rotation)])

    def compute_jacobian(self, configuration: Configuration) -> np.ndarray:
        target = self._check_target()
        root = configuration.frame_placement(configuration.frame_id(self.root))
        frame = configuration.frame_placement(configuration.frame_id(self.frame))
        j_root = configuration.frame_jacobian(configuration.frame_id(self.root))
        j_frame = configuration.frame_jacobian(configuration.frame_id(self.frame))
        r_root = root.rotation
        offset = frame.translation - root.translation
        out = np.empty((6, configuration.nv))
        # d/dt R_r^T (p_f - p_r) = R_r^T (v_f - v_r + [p_f - p_r]x w_r)
        out[:3] = r_root.T @ (j_frame[:3] - j_root[:3] + pin.skew(offset) @ j_root[3:])
        rel_rot = r_root.T @ frame.rotation
        # body angular velocity of R_r^T R_f is R_f^T (w_f - w_r)
        out[3:] = pin.Jlog3(target.rotation.T @ rel_rot) @ (frame.rotation.T @ (j_frame[3:] - j_root[3:]))
        return out
