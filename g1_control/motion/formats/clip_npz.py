"""Motion npz as BeyondMimic / mjlab write it, plus names: the motion library's file format.

Keys read and written by those projects: fps, joint_pos, joint_vel (T, 29), body_pos_w (T, B, 3),
body_quat_w (T, B, 4, w x y z), body_lin_vel_w, body_ang_vel_w. Their files store no names, and
the two projects order bodies differently. This module always writes joint_names and
body_names (and root_pos_w, root_quat_w, contacts, source, style, tags; and, for a clip that handles
an object, object_name, object_planes, object_pos_w, object_quat_w, object_hand_contacts; for one with
static scene shapes, scene_names, scene_plane_counts, scene_planes). Reading a file without
names, it takes the joints in g1.JOINT_NAMES order and the root from body 0 (the pelvis in both
projects), recomputes the bodies by forward kinematics and identifies each stored body by matching
it to the nearest recomputed one, refusing a file whose bodies match none (wrong joint order).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from g1_control.motion.clip import MotionClip
from g1_control.motion.exceptions import InvalidClipError, MotionFormatError
from g1_control.motion.objects import ObjectShape, ObjectTrack
from g1_control.robot import g1

REQUIRED = ("fps", "joint_pos", "joint_vel", "body_pos_w", "body_quat_w", "body_lin_vel_w", "body_ang_vel_w")
BODY_MATCH_TOLERANCE_M = 0.01


def write_clip_npz(clip: MotionClip, path: str | Path) -> None:
    extra: dict[str, np.ndarray] = {}
    if clip.object is not None:
        o = clip.object
        extra = {"object_name": np.array(o.shape.name), "object_planes": o.shape.planes, "object_pos_w": o.pos_w_m,
                 "object_quat_w": o.quat_wxyz, "object_hand_contacts": o.hand_contacts}
    if clip.scene:
        extra.update(scene_names=np.array([shape.name for shape in clip.scene]),
                     scene_plane_counts=np.array([shape.planes.shape[0] for shape in clip.scene]),
                     scene_planes=np.concatenate([shape.planes for shape in clip.scene]))
    # numpy's stub has a keyword `allow_pickle: bool` that mypy matches against **dict[str, ndarray].
    np.savez(
        path, **extra,  # type: ignore[arg-type]
        fps=np.array(clip.fps), joint_pos=clip.joint_pos_rad, joint_vel=clip.joint_vel_radps,
        body_pos_w=clip.body_pos_w_m, body_quat_w=clip.body_quat_wxyz, body_lin_vel_w=clip.body_lin_vel_w_mps,
        body_ang_vel_w=clip.body_ang_vel_w_radps, joint_names=np.array(clip.joint_names),
        body_names=np.array(clip.body_names), root_pos_w=clip.root_pos_w_m, root_quat_w=clip.root_quat_wxyz,
        contacts=clip.contacts, source=np.array(clip.source), style=np.array(clip.style),
        tags=np.array(clip.tags, dtype=str),
    )


def open_npz(path: Path):
    """np.load of an npz file, refusing anything that is not one (a pickle, text, a truncated zip)
    with one line naming the problem."""
    with path.open("rb") as fh:
        magic = fh.read(4)
    if magic != b"PK\x03\x04":
        raise MotionFormatError(f"{path}: not an npz file (it does not start with the zip signature)")
    try:
        return np.load(path, allow_pickle=False)
    except Exception as exc:
        raise MotionFormatError(f"{path}: not a readable npz file ({exc})") from None


def read_clip_npz(path: str | Path) -> MotionClip:
    path = Path(path)
    with open_npz(path) as data:
        missing = [k for k in REQUIRED if k not in data.files]
        if missing:
            raise MotionFormatError(f"{path}: missing keys {missing}; a motion npz has {list(REQUIRED)}")
        if "joint_names" in data.files and "body_names" in data.files:
            return _read_named(path, data)
        return _read_unnamed(path, data)


def _read_named(path: Path, data) -> MotionClip:
    joint_pos = data["joint_pos"]
    if joint_pos.ndim != 2 or joint_pos.shape[0] == 0:
        raise MotionFormatError(f"{path}: joint_pos has shape {joint_pos.shape}; expected (T, 29) with T >= 1")
    clip = MotionClip(
        fps=float(data["fps"]), joint_names=tuple(str(n) for n in data["joint_names"]),
        body_names=tuple(str(n) for n in data["body_names"]),
        root_pos_w_m=data["root_pos_w"] if "root_pos_w" in data.files else data["body_pos_w"][:, 0],
        root_quat_wxyz=data["root_quat_w"] if "root_quat_w" in data.files else data["body_quat_w"][:, 0],
        joint_pos_rad=joint_pos, joint_vel_radps=data["joint_vel"], body_pos_w_m=data["body_pos_w"],
        body_quat_wxyz=data["body_quat_w"], body_lin_vel_w_mps=data["body_lin_vel_w"],
        body_ang_vel_w_radps=data["body_ang_vel_w"],
        contacts=data["contacts"].astype(bool) if "contacts" in data.files
        else np.zeros((joint_pos.shape[0], 2), dtype=bool),
        source=str(data["source"]) if "source" in data.files else path.name,
        style=str(data["style"]) if "style" in data.files else "default",
        tags=tuple(str(t) for t in data["tags"]) if "tags" in data.files else (),
        object=_read_object(path, data), scene=_read_scene(path, data),
    )
    if "contacts" not in data.files:
        from g1_control.motion.contacts import foot_contacts

        feet = [clip.body_index(b) for b in g1.FOOT_BODIES]
        clip.contacts = foot_contacts(clip.body_pos_w_m[:, feet], clip.fps)
    try:
        return clip.validate()
    except InvalidClipError as exc:
        raise MotionFormatError(f"{path}: {exc}") from None


def _read_object(path: Path, data) -> ObjectTrack | None:
    keys = ("object_name", "object_planes", "object_pos_w", "object_quat_w", "object_hand_contacts")
    present = [k for k in keys if k in data.files]
    if not present:
        return None
    if len(present) != len(keys):
        raise MotionFormatError(f"{path}: has {present} but not {[k for k in keys if k not in present]}; "
                                "an object track needs all of them")
    planes = data["object_planes"]
    if planes.ndim != 2 or planes.shape[1] != 4:
        raise MotionFormatError(f"{path}: object_planes has shape {planes.shape}; expected (F, 4)")
    return ObjectTrack(ObjectShape(str(data["object_name"]), planes), data["object_pos_w"], data["object_quat_w"],
                       data["object_hand_contacts"])


def _read_scene(path: Path, data) -> tuple[ObjectShape, ...]:
    if "scene_names" not in data.files:
        return ()
    names, counts, planes = data["scene_names"], data["scene_plane_counts"], data["scene_planes"]
    if counts.shape != names.shape or planes.ndim != 2 or planes.shape[1] != 4 or counts.sum() != planes.shape[0]:
        raise MotionFormatError(f"{path}: scene_names {names.shape}, scene_plane_counts {counts.shape} and "
                                f"scene_planes {planes.shape} do not fit together")
    ends = np.cumsum(counts)
    return tuple(ObjectShape(str(n), planes[e - c:e]) for n, c, e in zip(names, counts, ends))


def _read_unnamed(path: Path, data) -> MotionClip:
    joint_pos = data["joint_pos"]
    if joint_pos.ndim != 2 or joint_pos.shape[1] != g1.NUM_JOINTS or joint_pos.shape[0] == 0:
        raise MotionFormatError(f"{path}: joint_pos has shape {joint_pos.shape}; expected (T, {g1.NUM_JOINTS})")
    body_pos = data["body_pos_w"]
    clip = MotionClip.from_joint_trajectory(float(data["fps"]), body_pos[:, 0], data["body_quat_w"][:, 0], joint_pos,
                                            source=path.name)
    # Identify the stored bodies among ours: each stored body must sit on one FK body.
    frames = np.unique(np.linspace(0, clip.num_frames - 1, 5).astype(int))
    dist = np.linalg.norm(body_pos[frames][:, :, None, :] - clip.body_pos_w_m[frames][:, None, :, :], axis=-1).max(0)
    match = dist.argmin(axis=1)
    worst = dist[np.arange(dist.shape[0]), match].max()
    if worst > BODY_MATCH_TOLERANCE_M:
        raise MotionFormatError(
            f"{path}: stored bodies do not match the G1 forward kinematics of joint_pos (off by {worst:.3f} m): "
            "the file's joint order is not g1.JOINT_NAMES; write it with joint_names/body_names")
    return clip
