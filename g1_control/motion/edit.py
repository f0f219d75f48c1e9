"""Cutting and joining clips."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from g1_control import rotations as quat
from g1_control.motion.clip import ARRAY_FIELDS, MotionClip
from g1_control.motion.exceptions import IncompatibleClipsError, InvalidClipError
from g1_control.motion.objects import ObjectTrack
from g1_control.rotations import yaw_of


def slice_clip(clip: MotionClip, start: int = 0, stop: int | None = None) -> MotionClip:
    """Frames [start, stop) (Python slice semantics, negative indices allowed) as a new clip."""
    frames = range(clip.num_frames)[slice(start, stop)]
    if len(frames) == 0:
        raise InvalidClipError(f"slice [{start}:{stop}] of '{clip.source}' ({clip.num_frames} frames) is empty")
    out = clip.copy()
    for name in ARRAY_FIELDS:
        setattr(out, name, np.array(getattr(clip, name)[frames.start:frames.stop], copy=True))
    if clip.object is not None:
        out.object = clip.object.take(slice(frames.start, frames.stop))
    return out.validate()




def transform_clip(clip: MotionClip, yaw_rad: float, translation_xy_m: np.ndarray) -> MotionClip:
    """The clip turned by yaw_rad about the world z axis, then shifted by translation_xy_m."""
    c, s = np.cos(yaw_rad), np.sin(yaw_rad)
    rot = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    q_yaw = np.array([np.cos(yaw_rad / 2), 0.0, 0.0, np.sin(yaw_rad / 2)])
    shift = np.array([translation_xy_m[0], translation_xy_m[1], 0.0])
    out = clip.copy()
    out.root_pos_w_m = clip.root_pos_w_m @ rot.T + shift
    out.root_quat_wxyz = quat.multiply(q_yaw, clip.root_quat_wxyz)
    out.body_pos_w_m = clip.body_pos_w_m @ rot.T + shift
    out.body_quat_wxyz = quat.multiply(q_yaw, clip.body_quat_wxyz)
    out.body_lin_vel_w_mps = clip.body_lin_vel_w_mps @ rot.T
    out.body_ang_vel_w_radps = clip.body_ang_vel_w_radps @ rot.T
    if clip.object is not None:
        out.object = clip.object.transformed(rot, q_yaw, shift)
    out.scene = tuple(shape.transformed(rot, shift) for shape in clip.scene)
    return out


def concatenate(clips: Sequence[MotionClip], align_root: bool = True) -> MotionClip:
    """One clip playing `clips` in turn. With align_root each clip is turned and shifted so that it
    starts where (x, y, heading) the previous one ended; heights are left as they are."""
    if not clips:
        raise InvalidClipError("concatenate needs at least one clip")
    first = clips[0]
    for other in clips[1:]:
        for attr in ("fps", "joint_names", "body_names"):
            if getattr(other, attr) != getattr(first, attr):
                raise IncompatibleClipsError(
                    f"cannot concatenate '{first.source}' and '{other.source}': different {attr} "
                    "(resample or convert them first)")
    parts = [first]
    for clip in clips[1:]:
        if align_root:
            prev_end = parts[-1]
            yaw = yaw_of(prev_end.root_quat_wxyz[-1]) - yaw_of(clip.root_quat_wxyz[0])
            c, s = np.cos(yaw), np.sin(yaw)
            start_xy = np.array([[c, -s], [s, c]]) @ clip.root_pos_w_m[0, :2]
            clip = transform_clip(clip, yaw, prev_end.root_pos_w_m[-1, :2] - start_xy)
        parts.append(clip)
    out = first.copy()
    for name in ARRAY_FIELDS:
        setattr(out, name, np.concatenate([getattr(p, name) for p in parts], axis=0))
    # One object track only when every part handles the same object; otherwise the result has none
    # (a clip has at most one object).
    tracks = [p.object for p in parts if p.object is not None]
    if len(tracks) == len(parts) and all(o.shape.equals(tracks[0].shape) for o in tracks):
        out.object = ObjectTrack(tracks[0].shape, np.concatenate([o.pos_w_m for o in tracks]),
                                 np.concatenate([o.quat_wxyz for o in tracks]),
                                 np.concatenate([o.hand_contacts for o in tracks]))
    else:
        out.object = None
    scene: list = []  # every part's shapes where that part put them (shared ones once)
    for shape in (shape for p in parts for shape in p.scene):
        if not any(shape.equals(known) for known in scene):
            scene.append(shape)
    out.scene = tuple(scene)
    out.source = " + ".join(p.source for p in parts if p.source)
    out.tags = tuple(dict.fromkeys(t for p in parts for t in p.tags))
    return out.validate()
