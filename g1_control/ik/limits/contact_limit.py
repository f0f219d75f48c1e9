"""Hold a foot (or any frame) where it touched down: an equality on the step that cancels the
frame's drift from its anchor pose, so a stance foot neither slides nor twists.

The anchor is set when contact begins (`set_anchor`); `release()` ends the contact.
With `position_only` the frame may roll about the anchor point (a point contact, e.g. a toe).
With `free_yaw` the sole stays flat where it was (position and tilt held) but may pivot about the
vertical, so the body can turn over a stance foot instead of twisting the leg.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from g1_control.ik import kernels
from g1_control.ik.configuration import Configuration
from g1_control.ik.limits.base import Limit, RowConstraint


class ContactLimit(Limit):
    def __init__(self, frame: str, position_only: bool = False, free_yaw: bool = False) -> None:
        self.frame = frame
        self.position_only = position_only
        self.free_yaw = free_yaw
        self.anchor: pin.SE3 | None = None
        self._fid: int | None = None

    @property
    def active(self) -> bool:
        return self.anchor is not None

    def set_anchor(self, pose_w: pin.SE3) -> None:
        self.anchor = pin.SE3(pose_w)
        quat = pin.Quaternion(self.anchor.rotation)
        self._anchor7 = np.array([*self.anchor.translation, quat.w, quat.x, quat.y, quat.z])

    def release(self) -> None:
        self.anchor = None

    def position_drift(self, configuration: Configuration) -> float:
        """Largest per-axis distance (m) of the frame origin from the anchor."""
        assert self.anchor is not None
        current = configuration.data.oMf[self._frame_id(configuration)].translation
        return float(np.abs(current - self._anchor7[:3]).max())

    def error(self, configuration: Configuration) -> np.ndarray:
        """Drift of the frame from the anchor: position (m, world) and rotation (rad, frame axes)."""
        assert self.anchor is not None
        current = configuration.frame_placement(self._frame_id(configuration))
        pos = current.translation - self.anchor.translation
        if self.position_only:
            return pos
        if self.free_yaw:
            # the frame's z axis must stay orthogonal to the anchor's x and y axes (tilt held)
            z_axis = current.rotation[:, 2]
            return np.concatenate([pos, [self.anchor.rotation[:, 0] @ z_axis, self.anchor.rotation[:, 1] @ z_axis]])
        return np.concatenate([pos, pin.log3(self.anchor.rotation.T @ current.rotation)])

    def _frame_id(self, configuration: Configuration) -> int:
        if self._fid is None:
            self._fid = configuration.frame_id(self.frame)
        return self._fid

    def compute(self, configuration: Configuration, dt_s: float) -> RowConstraint | None:
        if self.anchor is None:
            return None
        fid = self._frame_id(configuration)
        if not (self.position_only or self.free_yaw):
            return self._full_hold(configuration, fid)
        current = configuration.frame_placement(fid)
        jac = configuration.frame_jacobian(fid)  # a fresh array: rows are rewritten in place
        if self.position_only:
            err = self.anchor.translation - current.translation  # = -error
            return RowConstraint(jac[:3], err, err, equality=True)
        # free yaw: position and tilt held
        z_axis = current.rotation[:, 2]
        tilt = np.empty((2, configuration.nv))
        neg_err = np.empty(5)
        neg_err[:3] = self.anchor.translation - current.translation
        for i in range(2):
            axis = self.anchor.rotation[:, i]
            neg_err[3 + i] = -(axis @ z_axis)
            # d/dt (a . z) = a . (w x z) = (z x a) . w
            tilt[i] = np.cross(z_axis, axis) @ jac[3:]
        return RowConstraint(np.vstack([jac[:3], tilt]), neg_err, neg_err, equality=True)

    def _full_hold(self, configuration: Configuration, fid: int) -> RowConstraint:
        # Full hold: the frame task's rows (ik/kernels.py) with the anchor as target, J dq = -e.
        rows = np.empty((6, configuration.nv))
        neg_err = np.empty(6)
        kernels.frame_rows(configuration.joint_jacobians_w, configuration.placements([fid]), self._anchor7[None],
                           configuration.support_masks((fid,)), _FULL, _ROW0, rows, neg_err)
        np.negative(neg_err, out=neg_err)
        return RowConstraint(rows, neg_err, neg_err, equality=True)


_FULL = np.array([True])
_ROW0 = np.zeros(1, dtype=np.int64)
