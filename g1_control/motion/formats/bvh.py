"""BVH motion capture (e.g. LAFAN1) -> world joint positions.

Hierarchy: ROOT/JOINT blocks with OFFSET and CHANNELS; End Sites are skipped. Each joint's
rotation channels compose in the order listed (intrinsic: R = R_c1 R_c2 R_c3), as the BVH
convention has it. LAFAN1 is in centimetres and y-up: `unit_m` scales (0.01 for cm) and
`y_up=True` turns y-up into this project's z-up ((x, y, z) -> (x, -z, y), a +90 deg turn about x).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from g1_control.motion.exceptions import MotionFormatError
from g1_control.motion.human import HumanMotion

_AXES = {"X": 0, "Y": 1, "Z": 2}


@dataclass
class _Joint:
    name: str
    parent: int
    offset: np.ndarray
    channels: list[str] = field(default_factory=list)


def _rot(axis: int, angle_rad: np.ndarray) -> np.ndarray:
    c, s = np.cos(angle_rad), np.sin(angle_rad)
    m = np.zeros(angle_rad.shape + (3, 3))
    i, j = [(1, 2), (2, 0), (0, 1)][axis]
    m[..., axis, axis] = 1.0
    m[..., i, i] = c
    m[..., j, j] = c
    m[..., i, j] = -s
    m[..., j, i] = s
    return m


def read_bvh(path: str | Path, unit_m: float = 0.01, y_up: bool = True, height_m: float | None = None) -> HumanMotion:
    path = Path(path)
    try:
        lines = path.read_text().splitlines()
    except (OSError, UnicodeDecodeError) as exc:
        raise MotionFormatError(f"{path}: cannot read ({exc})") from None
    joints: list[_Joint] = []
    stack: list[int] = []
    i = 0
    in_end_site = False
    pending: int | None = None
    while i < len(lines):
        tokens = lines[i].split()
        i += 1
        if not tokens:
            continue
        key = tokens[0].upper()
        if key == "HIERARCHY":
            continue
        if key in ("ROOT", "JOINT"):
            if len(tokens) < 2:
                raise MotionFormatError(f"{path}: line {i}: {key} without a name")
            joints.append(_Joint(tokens[1], stack[-1] if stack else -1, np.zeros(3)))
            pending = len(joints) - 1
        elif key == "END":
            in_end_site = True
            pending = None
        elif key == "{":
            stack.append(pending if pending is not None else -2)
        elif key == "}":
            if not stack:
                raise MotionFormatError(f"{path}: line {i}: unbalanced '}}'")
            top = stack.pop()
            if top == -2:
                in_end_site = False
        elif key == "OFFSET":
            if len(tokens) != 4:
                raise MotionFormatError(f"{path}: line {i}: OFFSET needs 3 numbers")
            if not in_end_site and stack and stack[-1] >= 0:
                try:
                    joints[stack[-1]].offset = np.array([float(t) for t in tokens[1:]])
                except ValueError as exc:
                    raise MotionFormatError(f"{path}: line {i}: OFFSET: {exc}") from None
        elif key == "CHANNELS":
            if not stack or stack[-1] < 0:
                raise MotionFormatError(f"{path}: line {i}: CHANNELS outside a joint")
            try:
                count = int(tokens[1])
            except (IndexError, ValueError):
                raise MotionFormatError(f"{path}: line {i}: CHANNELS needs a count") from None
            names = tokens[2:]
            if len(names) != count:
                raise MotionFormatError(f"{path}: line {i}: joint '{joints[stack[-1]].name}' declares {count} channels "
                                        f"but lists {len(names)}")
            for ch in names:
                if ch[:1].upper() not in _AXES or ch[1:].lower() not in ("position", "rotation"):
                    raise MotionFormatError(f"{path}: line {i}: unknown channel '{ch}'")
            joints[stack[-1]].channels = names
        elif key == "MOTION":
            break
    if not joints:
        raise MotionFormatError(f"{path}: no HIERARCHY joints found")
    for joint in joints:
        rot = [c for c in joint.channels if c.lower().endswith("rotation")]
        if len(rot) != 3:
            raise MotionFormatError(f"{path}: joint '{joint.name}' has {len(rot)} rotation channels; expected 3 "
                                    "(missing channels)")
    if not any(c.lower().endswith("position") for c in joints[0].channels):
        raise MotionFormatError(f"{path}: root joint '{joints[0].name}' has no position channels")
    header: dict[str, str] = {}
    while i < len(lines) and len(header) < 2:
        text = lines[i].strip()
        i += 1
        if text.lower().startswith("frames:"):
            header["frames"] = text.split(":", 1)[1]
        elif text.lower().startswith("frame time:"):
            header["time"] = text.split(":", 1)[1]
    try:
        n_frames, frame_time = int(header["frames"]), float(header["time"])
    except (KeyError, ValueError):
        raise MotionFormatError(f"{path}: MOTION section needs 'Frames:' and 'Frame Time:'") from None
    if n_frames == 0:
        raise MotionFormatError(f"{path}: zero frames")
    if frame_time <= 0:
        raise MotionFormatError(f"{path}: Frame Time {frame_time}; expected > 0")
    n_channels = sum(len(j.channels) for j in joints)
    rows = []
    for k, text in enumerate(lines[i:i + n_frames]):
        parts = text.split()
        if len(parts) != n_channels:
            raise MotionFormatError(f"{path}: frame {k} has {len(parts)} values; the hierarchy declares {n_channels} "
                                    "channels (missing channels)")
        try:
            values = np.array([float(p) for p in parts])
        except ValueError as exc:
            raise MotionFormatError(f"{path}: frame {k}: {exc}") from None
        if not np.all(np.isfinite(values)):
            raise MotionFormatError(f"{path}: frame {k} contains NaN or inf")
        rows.append(values)
    if len(rows) != n_frames:
        raise MotionFormatError(f"{path}: header says {n_frames} frames but the file has {len(rows)}")
    motion = np.array(rows)
    positions = _forward(joints, motion) * unit_m
    if y_up:
        positions = np.stack([positions[..., 0], -positions[..., 2], positions[..., 1]], axis=-1)
    return HumanMotion(positions, tuple(j.name for j in joints), 1.0 / frame_time, height_m, path.name).validate()


def _forward(joints: list[_Joint], motion: np.ndarray) -> np.ndarray:
    t = motion.shape[0]
    world_rot = np.zeros((len(joints), t, 3, 3))
    world_pos = np.zeros((len(joints), t, 3))
    col = 0
    for idx, joint in enumerate(joints):
        local_rot = np.broadcast_to(np.eye(3), (t, 3, 3)).copy()
        local_pos = np.broadcast_to(joint.offset, (t, 3)).copy()
        for ch in joint.channels:
            axis = _AXES[ch[0].upper()]
            if ch.lower().endswith("position"):
                local_pos[:, axis] = motion[:, col]
            else:
                local_rot = local_rot @ _rot(axis, np.deg2rad(motion[:, col]))
            col += 1
        if joint.parent < 0:
            world_rot[idx] = local_rot
            world_pos[idx] = local_pos
        else:
            world_rot[idx] = world_rot[joint.parent] @ local_rot
            world_pos[idx] = world_pos[joint.parent] + np.einsum("tij,tj->ti", world_rot[joint.parent], local_pos)
    return np.transpose(world_pos, (1, 0, 2))
