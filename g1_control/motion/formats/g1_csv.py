"""Unitree's G1 motion CSV (the LAFAN1-retargeted release): no header, one frame per line,
36 columns = root x y z (m), root quaternion x y z w, then the 29 joint angles (rad) in
g1.JOINT_NAMES order. The file stores no frame rate; Unitree's release is 30 fps.

Values are written with Python's shortest round-trip repr, so CSV -> MotionClip -> CSV returns
the same numbers bit for bit.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from g1_control.motion.clip import MotionClip
from g1_control.motion.exceptions import MotionFormatError
from g1_control.robot import g1

NUM_COLUMNS = 7 + g1.NUM_JOINTS
DEFAULT_FPS = 30.0


def read_g1_csv(path: str | Path, fps: float = DEFAULT_FPS, style: str = "default") -> MotionClip:
    path = Path(path)
    rows: list[list[float]] = []
    try:
        text = path.read_bytes().decode("utf-8")
    except UnicodeDecodeError as exc:
        raise MotionFormatError(f"{path}: not a UTF-8 text file (byte {exc.start}); a G1 CSV is text") from None
    for lineno, line in enumerate(text.splitlines(), start=1):
        if not line.strip():
            continue
        parts = line.strip().split(",")
        if len(parts) != NUM_COLUMNS:
            raise MotionFormatError(f"{path}: line {lineno} has {len(parts)} columns; a G1 CSV has {NUM_COLUMNS} "
                                    "(root xyz, root quaternion xyzw, 29 joints)")
        try:
            values = [float(p) for p in parts]
        except ValueError as exc:
            raise MotionFormatError(f"{path}: line {lineno}: {exc}") from None
        if not np.all(np.isfinite(values)):
            raise MotionFormatError(f"{path}: frame {len(rows)} (line {lineno}) contains NaN or inf")
        rows.append(values)
    if not rows:
        raise MotionFormatError(f"{path}: no frames (empty file)")
    data = np.array(rows)
    quat_xyzw = data[:, 3:7]
    norms = np.linalg.norm(quat_xyzw, axis=1)
    bad = np.flatnonzero(np.abs(norms - 1.0) > 1e-3)
    if bad.size:
        raise MotionFormatError(f"{path}: frame {bad[0]} root quaternion has norm {norms[bad[0]]:.4f}; expected 1")
    return MotionClip.from_joint_trajectory(fps, data[:, :3], quat_xyzw[:, [3, 0, 1, 2]], data[:, 7:],
                                            source=path.name, style=style)


def write_g1_csv(clip: MotionClip, path: str | Path) -> None:
    if clip.joint_names != g1.JOINT_NAMES:
        raise MotionFormatError(f"{path}: a G1 CSV stores joints in g1.JOINT_NAMES order; the clip has another order")
    q = clip.root_quat_wxyz
    data = np.concatenate([clip.root_pos_w_m, q[:, [1, 2, 3, 0]], clip.joint_pos_rad], axis=1)
    with Path(path).open("w") as fh:
        fh.writelines(",".join(repr(v) for v in row) + "\n" for row in data.tolist())
