"""`HumanMotion`: human motion capture as world joint positions, the retargeter's input.

    positions_w_m   (T, J, 3) joint centres in the world, m, z-up, ground at z = 0
    joint_names     (J,) names in the data's own skeleton (see skeletons.py)
    fps             frames per second (Hz)
    height_m        the performer's height when known (for scaling to the G1), else None
    source          file name
    object          the handled object's track (motion/objects.py), or None
    scene           static shapes around the motion (climbing boxes), world coordinates
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from g1_control.motion.exceptions import InvalidClipError
from g1_control.motion.objects import ObjectShape, ObjectTrack


@dataclass
class HumanMotion:
    positions_w_m: np.ndarray
    joint_names: tuple[str, ...]
    fps: float
    height_m: float | None = None
    source: str = ""
    object: ObjectTrack | None = None
    """The object the performer handles (pose per frame), when the data has one."""
    scene: tuple[ObjectShape, ...] = ()
    """Static shapes the performer moves on (climbing boxes), world coordinates, human scale."""

    def validate(self) -> HumanMotion:
        where = f"'{self.source}'" if self.source else "human motion"
        pos = self.positions_w_m
        if pos.ndim != 3 or pos.shape[2] != 3:
            raise InvalidClipError(f"{where}: positions have shape {pos.shape}; expected (T, J, 3)")
        if pos.shape[0] == 0:
            raise InvalidClipError(f"{where} has zero frames")
        if pos.shape[1] != len(self.joint_names):
            raise InvalidClipError(f"{where}: {pos.shape[1]} joints in the data but {len(self.joint_names)} names")
        finite = np.isfinite(pos).all(axis=(1, 2))
        if not finite.all():
            raise InvalidClipError(f"{where}: NaN or inf at frame {int(np.flatnonzero(~finite)[0])}")
        if not (np.isfinite(self.fps) and self.fps > 0):
            raise InvalidClipError(f"{where}: fps is {self.fps}; expected a positive number")
        if self.object is not None:
            self.object.validate(pos.shape[0], where)
        return self

    @property
    def num_frames(self) -> int:
        return int(self.positions_w_m.shape[0])

    def joint(self, name: str) -> np.ndarray:
        """(T, 3) trajectory of one joint."""
        return self.positions_w_m[:, self.joint_names.index(name)]
