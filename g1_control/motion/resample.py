"""Change a clip's frame rate: joints and root position interpolate linearly, the root
orientation by slerp; body poses are then recomputed by forward kinematics (so they stay
consistent with the joints) and velocities by differences. Contacts take the nearest frame."""

from __future__ import annotations

import numpy as np

from g1_control.motion.clip import MotionClip
from g1_control.motion.exceptions import InvalidClipError
from g1_control.motion.interpolation import interpolate_positions, interpolate_quaternions, resample_times


def resample(clip: MotionClip, new_fps: float) -> MotionClip:
    if not (np.isfinite(new_fps) and new_fps > 0):
        raise InvalidClipError(f"cannot resample '{clip.source}' to fps {new_fps}; expected a positive number")
    times = resample_times(clip.num_frames, clip.fps, new_fps)
    nearest = np.clip(np.rint(times * clip.fps).astype(int), 0, clip.num_frames - 1)
    return MotionClip.from_joint_trajectory(
        new_fps,
        interpolate_positions(clip.root_pos_w_m, clip.fps, times),
        interpolate_quaternions(clip.root_quat_wxyz, clip.fps, times),
        interpolate_positions(clip.joint_pos_rad, clip.fps, times),
        contacts=clip.contacts[nearest], source=clip.source, style=clip.style, tags=clip.tags,
        body_names=clip.body_names,
        object=None if clip.object is None else clip.object.resampled(clip.fps, times), scene=clip.scene,
    )
