"""Where the robot is, from what a robot has: a world pose from the IMU and contact-aided leg
kinematics, anchored where the run starts (the origin, heading 0: the frame a launch file's scene
is written in when the robot starts at its origin).

A foot in stance does not move: at touchdown it is anchored where the current estimate puts it,
and while it stands the base sits at its anchor minus the foot's offset from the base (forward
kinematics with the IMU's orientation). Between anchors the estimator's velocity (leg kinematics +
accelerometer, estimation/estimator.py) carries the position, and a first-order correction pulls it
to the anchored value, so a change of stance feet never makes it jump. Stance comes from a
controller's contact schedule where one runs (the WBC's), else from the estimator's stance weights
(the lower foot; both feet within a few millimetres of each other: double support). Heading is the
IMU's yaw relative to its yaw at the start: on a robot it drifts as the IMU's yaw drifts.

Nothing here reads simulator ground truth. `g1 bench odometry` measures the drift against it.

    odometry = LegOdometry()
    odometry.reset(state)
    pose = odometry.update(state)          # WorldPose(x_m, y_m, z_m, yaw_rad) in the start frame
"""

from __future__ import annotations

import math

import numpy as np

from g1_control.estimation.estimator import StateEstimator
from g1_control.rotations import wrap_angle, yaw_of
from g1_control.types import RobotState, WorldPose

STANCE_WEIGHT = 0.25
"""A foot with at least this stance weight stands (the estimator's soft weight: the higher foot of
two within ~3 mm of each other still has more than this, so both stand in double support)."""


class LegOdometry:
    def __init__(self, estimator: StateEstimator | None = None, correction_tau_s: float = 0.05,
                 shared: bool = False):
        """estimator: a StateEstimator this odometry updates itself (one update per call of update()),
        or, with shared=True, one its owner updates (the loop's) just before each call of update():
        the odometry then reads its latest estimate and kinematics (no second forward kinematics)."""
        if not correction_tau_s > 0:
            raise ValueError(f"LegOdometry correction_tau_s must be > 0; got {correction_tau_s}")
        if shared and estimator is None:
            raise ValueError("LegOdometry shared=True needs the estimator it shares")
        self.estimator = estimator or StateEstimator()
        self.shared = shared
        self.correction_tau_s = correction_tau_s
        self.position_m = np.zeros(3)
        self.anchors_m = np.zeros((2, 3))
        self._anchored = np.zeros(2, dtype=bool)
        self._yaw0 = 0.0
        self._rot0 = np.eye(3)
        self._last_t: float | None = None
        self.pose = WorldPose(0.0, 0.0, 0.0, 0.0, 0.0)

    def reset(self, state: RobotState) -> WorldPose:
        """Anchor the start frame here: the pelvis at (0, 0) over the floor, heading 0, both feet standing."""
        if self.shared:
            est = self.estimator.estimate
        else:
            self.estimator.reset(state)
            est = self.estimator.update(state)
        self._yaw0 = yaw_of(state.imu_quat_wxyz)
        c, s = math.cos(-self._yaw0), math.sin(-self._yaw0)
        self._rot0 = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
        offsets = self._offsets()
        self.position_m = np.array([0.0, 0.0, est.pelvis_height_m or -float(offsets[:, 2].min())])
        self.anchors_m = self.position_m + offsets
        self._anchored[:] = True
        self._last_t = state.t_s
        self.pose = WorldPose(state.t_s, 0.0, 0.0, float(self.position_m[2]), 0.0)
        return self.pose

    def restart(self) -> None:
        """Anchor the start frame at the next update() (a shared estimator updated first)."""
        self._last_t = None

    def update(self, state: RobotState, contacts: np.ndarray | None = None) -> WorldPose:
        """contacts: (left, right) in stance by a controller's schedule; None: the estimator's weights."""
        if self._last_t is None:
            return self.reset(state)
        est = self.estimator.estimate if self.shared else self.estimator.update(state, contacts)
        dt = max(0.0, state.t_s - self._last_t)
        self._last_t = state.t_s
        stance = np.asarray(contacts, dtype=bool) if contacts is not None else est.stance_weight >= STANCE_WEIGHT
        offsets = self._offsets()
        p = self.position_m
        p += self._rot0 @ est.base_linvel_w_mps * dt
        kin, n = np.zeros(3), 0
        for i in range(2):
            if not stance[i]:
                self._anchored[i] = False
                continue
            if not self._anchored[i]:  # touchdown: anchored where the estimate puts it (continuity)
                self.anchors_m[i] = p + offsets[i]
                self._anchored[i] = True
            kin += self.anchors_m[i] - offsets[i]
            n += 1
        if n:
            p += dt / (self.correction_tau_s + dt) * (kin / n - p)
        self.pose = WorldPose(state.t_s, float(p[0]), float(p[1]), float(p[2]),
                              float(wrap_angle(est.yaw_rad - self._yaw0)))
        return self.pose

    def _offsets(self) -> np.ndarray:
        """Sole centres minus the base position, in the start frame's axes."""
        return self.estimator.sole_offsets_w_m() @ self._rot0.T


__all__ = ["STANCE_WEIGHT", "LegOdometry", "WorldPose"]
