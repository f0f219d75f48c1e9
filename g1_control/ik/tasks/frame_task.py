"""Put a robot frame at a world pose.

Error: position p - p* (world, m) and orientation log(R*^T R) (rad, in the frame's own axes).
Keeping the two apart (rather than one SE(3) log) lets a position-only task (orientation cost 0)
pull the point straight to its target, which is what mocap keypoints need.
"""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin

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
    """Frame `frame` at `target` (pin.SE3). cost: scalar, (2,) = (position, orientation) or (6,)."""

    def __init__(self, frame: str, position_cost: float | np.ndarray = 1.0, orientation_cost: float | np.ndarray = 1.0,
                 gain: float = 1.0, lm_damping: float = 0.0) -> None:
        pos = check_cost(f"FrameTask('{frame}') position", position_cost, 3)
        ori = check_cost(f"FrameTask('{frame}') orientation", orientation_cost, 3)
        super().__init__(np.concatenate([np.broadcast_to(pos, 3), np.broadcast_to(ori, 3)]), gain, lm_damping)
        self.frame = frame
        self._track_orientation = bool(np.any(self.cost[3:] > 0.0))
        self.target: pin.SE3 | None = None
        self._fid: int | None = None
        self._error = np.zeros(6)
        self._jac: np.ndarray | None = None

    def set_target(self, target: pin.SE3) -> None:
        self.target = target

    def set_target_position(self, position_w_m: np.ndarray) -> None:
        """Move only the target position (orientation kept, identity if none yet)."""
        if self.target is None:
            self.target = pin.SE3(np.eye(3), np.asarray(position_w_m, dtype=float).copy())
        else:
            self.target.translation = np.asarray(position_w_m, dtype=float)

    def set_target_from_configuration(self, configuration: Configuration) -> None:
        self.target = pin.SE3(configuration.frame_placement(self._frame_id(configuration)))

    def _frame_id(self, configuration: Configuration) -> int:
        if self._fid is None:
            self._fid = configuration.frame_id(self.frame)
        return self._fid

    def _check_target(self) -> pin.SE3:
        if self.target is None:
            raise TaskDefinitionError(f"FrameTask('{self.frame}') has no target; call set_target first")
        return self.target

    def compute_error(self, configuration: Configuration) -> np.ndarray:
        target = self._check_target()
        current = configuration.frame_placement(self._frame_id(configuration))
        self._error[:3] = current.translation - target.translation
        if self._track_orientation:
            self._error[3:] = pin.log3(target.rotation.T @ current.rotation)
        return self._error

    def compute_error_and_jacobian(self, configuration: Configuration) -> tuple[np.ndarray, np.ndarray]:
        target = self._check_target()
        fid = self._frame_id(configuration)
        current = configuration.frame_placement(fid)
        jac = configuration.frame_jacobian(fid)
        error = np.empty(6)
        error[:3] = current.translation - target.translation
        if self._track_orientation:
            rot = current.rotation
            rel = target.rotation.T @ rot
            error[3:] = pin.log3(rel)
            jac[3:] = pin.Jlog3(rel) @ (rot.T @ jac[3:])
        else:
            error[3:] = 0.0
            jac[3:] = 0.0
        return error, jac

    def compute_jacobian(self, configuration: Configuration) -> np.ndarray:
        target = self._check_target()
        fid = self._frame_id(configuration)
        current = configuration.frame_placement(fid)
        jac = configuration.frame_jacobian(fid)
        out = np.empty_like(jac)
        out[:3] = jac[:3]
        if self._track_orientation:
            # d log(R*^T R) = Jlog3 * (body angular velocity) and body = R^T world.
            out[3:] = pin.Jlog3(target.rotation.T @ current.rotation) @ (current.rotation.T @ jac[3:])
        else:
            out[3:] = 0.0
        return out


def stack_frame_tasks(configuration: Configuration, tasks: list[FrameTask]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(J, gain * e, w^2) of many frame tasks stacked, the same rows compute_error_and_jacobian gives
    (position-only tasks contribute their 3 position rows only). One pass with few numpy calls per
    task: the per-tick path of the solver, where Python call overhead dominates the arithmetic."""
    rows = sum(6 if t._track_orientation else 3 for t in tasks)
    nv = configuration.nv
    jac = np.empty((rows, nv))
    err = np.empty(rows)
    w2 = np.empty(rows)
    model, data = configuration.model, configuration.data
    lwa = pin.LOCAL_WORLD_ALIGNED
    r = 0
    for task in tasks:
        target = task._check_target()
        fid = task._fid if task._fid is not None else task._frame_id(configuration)
        current = data.oMf[fid]
        full = pin.getFrameJacobian(model, data, fid, lwa)
        jac[r:r + 3] = full[:3]
        err[r:r + 3] = current.translation
        err[r:r + 3] -= target.translation
        err[r:r + 3] *= task.gain
        w2[r:r + 3] = task._w2[:3]
        if task._track_orientation:
            rot = current.rotation
            rel = target.rotation.T @ rot
            err[r + 3:r + 6] = task.gain * pin.log3(rel)
            jac[r + 3:r + 6] = pin.Jlog3(rel) @ (rot.T @ full[3:])
            w2[r + 3:r + 6] = task._w2[3:]
            r += 6
        else:
            r += 3
    return jac, err, w2
