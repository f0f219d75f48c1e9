"""Put a robot frame at a world pose.

Error: position p - p* (world, m) and orientation log(R*^T R) (rad, in the frame's own axes).
Keeping the two apart (rather than one SE(3) log) lets a position-only task (orientation cost 0)
pull the point straight to its target, which is what mocap keypoints need.
"""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin

from g1_control.ik import kernels
from g1_control.ik.configuration import Configuration
from g1_control.ik.exceptions import TaskDefinitionError
from g1_control.ik.tasks.base import Task, check_cost


def pose_from_vector(pose_xyz_wxyz: np.ndarray, owner: str = "target") -> pin.SE3:
    """SE3 from a 7-vector (x, y, z, qw, qx, qy, qz), the layout KinematicReference uses."""
    v = np.asarray(pose_xyz_wxyz, dtype=float)
    if v.shape != (7,) or not np.isfinite(v).all():
        raise TaskDefinitionError(f"{owner} must be 7 finite numbers (x, y, z, qw, qx, qy, qz). Got {v!r}")
    w, x, y, z = v[3:]
    norm = math.sqrt(w * w + x * x + y * y + z * z)
    if norm < 1e-9:
        raise TaskDefinitionError(f"{owner} quaternion is zero; expected a unit quaternion (qw, qx, qy, qz)")
    return pin.SE3(pin.Quaternion(w / norm, x / norm, y / norm, z / norm).toRotationMatrix(), v[:3].copy())


class FrameTask(Task):
    """Frame `frame` at a target pose. cost: scalar, (2,) = (position, orientation) or (6,).

    The target is kept as 7 numbers (x, y, z, qw, qx, qy, qz), the KinematicReference layout, so a
    reference streams into the task without building pinocchio objects; `target` gives it as SE3."""

    def __init__(self, frame: str, position_cost: float | np.ndarray = 1.0, orientation_cost: float | np.ndarray = 1.0,
                 gain: float = 1.0, lm_damping: float = 0.0) -> None:
        pos = check_cost(f"FrameTask('{frame}') position", position_cost, 3)
        ori = check_cost(f"FrameTask('{frame}') orientation", orientation_cost, 3)
        super().__init__(np.concatenate([np.broadcast_to(pos, 3), np.broadcast_to(ori, 3)]), gain, lm_damping)
        self.frame = frame
        self._track_orientation = bool(np.any(self.cost[3:] > 0.0))
        self._target7 = np.array([0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0])
        self._has_target = False
        self._fid: int | None = None

    @property
    def target(self) -> pin.SE3 | None:
        """The target as an SE3 (a copy: change it with set_target / set_target_position)."""
        if not self._has_target:
            return None
        return pose_from_vector(self._target7, f"FrameTask('{self.frame}') target")

    def set_target(self, target: pin.SE3) -> None:
        quat = pin.Quaternion(target.rotation)
        self._target7[:3] = target.translation
        self._target7[3:] = (quat.w, quat.x, quat.y, quat.z)
        self._has_target = True

    def set_target_vector(self, pose_xyz_wxyz: np.ndarray) -> None:
        """Target from 7 numbers (x, y, z, qw, qx, qy, qz), taken as given: the caller checked them
        (finite, quaternion not zero; it need not be normalised)."""
        self._target7[:] = pose_xyz_wxyz
        self._has_target = True

    def set_target_position(self, position_w_m: np.ndarray) -> None:
        """Move only the target position (orientation kept, identity if none yet)."""
        self._target7[:3] = position_w_m
        self._has_target = True

    def set_target_from_configuration(self, configuration: Configuration) -> None:
        self.set_target(configuration.frame_placement(self._frame_id(configuration)))

    def _frame_id(self, configuration: Configuration) -> int:
        if self._fid is None:
            self._fid = configuration.frame_id(self.frame)
        return self._fid

    def _check_target(self) -> None:
        if not self._has_target:
            raise TaskDefinitionError(f"FrameTask('{self.frame}') has no target; call set_target first")

    def compute_error_and_jacobian(self, configuration: Configuration) -> tuple[np.ndarray, np.ndarray]:
        """(6,) error and (6, nv) Jacobian; a position-only task has zero orientation rows."""
        self._check_target()
        jac = np.zeros((6, configuration.nv))
        err = np.zeros(6)
        fid = self._frame_id(configuration)
        kernels.frame_rows(configuration.joint_jacobians_w, configuration.placements([fid]), self._target7[None],
                           configuration.support_masks((fid,)), np.array([self._track_orientation]),
                           np.zeros(1, dtype=np.int64), jac, err)
        return err, jac

    def compute_error(self, configuration: Configuration) -> np.ndarray:
        return self.compute_error_and_jacobian(configuration)[0]

    def compute_jacobian(self, configuration: Configuration) -> np.ndarray:
        return self.compute_error_and_jacobian(configuration)[1]


class _Layout:
    """Row layout of a set of frame tasks, reused while the set and its costs stay the same."""

    def __init__(self, configuration: Configuration, tasks: list[FrameTask]) -> None:
        self.frame_ids = [t._frame_id(configuration) for t in tasks]
        self.masks = configuration.support_masks(tuple(self.frame_ids))
        self.orientation = np.array([t._track_orientation for t in tasks])
        sizes = [6 if t._track_orientation else 3 for t in tasks]
        self.row_start = np.concatenate([[0], np.cumsum(sizes)[:-1]]).astype(np.int64)
        self.rows = int(sum(sizes))
        self.w2 = np.concatenate([t._w2[:n] for t, n in zip(tasks, sizes)])
        self.gains = np.concatenate([np.full(n, t.gain) for t, n in zip(tasks, sizes)])


def stack_frame_tasks(configuration: Configuration, tasks: list[FrameTask]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(J, gain * e, w^2) of many frame tasks stacked, the rows compute_error_and_jacobian gives
    (position-only tasks contribute their 3 position rows only), in one compiled call."""
    for task in tasks:
        if not task._has_target:
            task._check_target()
    key = tuple((t.frame, t.gain, t._w2.tobytes()) for t in tasks)
    cache = configuration.layout_cache
    layout: _Layout | None = cache.get(key)
    if layout is None:
        if len(cache) > 256:
            cache.clear()
        layout = cache[key] = _Layout(configuration, tasks)
    jac = np.empty((layout.rows, configuration.nv))
    err = np.empty(layout.rows)
    kernels.frame_rows(configuration.joint_jacobians_w, configuration.placements(layout.frame_ids),
                       np.array([t._target7 for t in tasks]), layout.masks, layout.orientation, layout.row_start,
                       jac, err)
    err *= layout.gains
    return jac, err, layout.w2
