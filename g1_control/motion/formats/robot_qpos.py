"""G1 clips written by other retargeters, as root pose + the 29 joint angles per frame.

- holosoma_retargeting (Amazon FAR) result npz: `qpos` (T, 36) in MuJoCo's layout, x y z, quaternion
  w x y z, then the 29 joints in Unitree's order; (T, 43) when an object's pose (x y z, w x y z) is
  appended, which is dropped here (the file does not say what the object is); `fps` (holosoma
  writes 30).
- GMR (General Motion Retargeting) pickle: a dict with `fps`, `root_pos` (T, 3), `root_rot` (T, 4,
  quaternion x y z w) and `dof_pos` (T, 29, Unitree's order). Read with an unpickler that builds
  only numpy arrays and plain containers, so a pickle cannot run code here.

Both store no contact labels; MotionClip.from_joint_trajectory derives them from foot motion.
"""

from __future__ import annotations

import pickle
from pathlib import Path

import numpy as np

from g1_control.motion.clip import MotionClip
from g1_control.motion.exceptions import MotionFormatError
from g1_control.robot import g1

HOLOSOMA_FPS = 30.0


def is_holosoma_npz(keys: list[str]) -> bool:
    return "qpos" in keys and "joint_pos" not in keys


def read_holosoma_npz(path: str | Path, fps: float | None = None) -> MotionClip:
    path = Path(path)
    try:
        with np.load(path, allow_pickle=False) as data:
            if "qpos" not in data.files:
                raise MotionFormatError(f"{path}: no 'qpos' array; a holosoma result npz has qpos (T, 36)")
            qpos = np.asarray(data["qpos"], dtype=float)
            stored_fps = float(data["fps"]) if "fps" in data.files else None
    except (OSError, ValueError) as exc:
        raise MotionFormatError(f"{path}: not a readable npz file ({exc})") from None
    width = 7 + g1.NUM_JOINTS
    if qpos.ndim != 2 or qpos.shape[1] not in (width, width + 7):
        raise MotionFormatError(f"{path}: qpos has shape {qpos.shape}; expected (T, {width}) (root x y z, "
                                f"quaternion w x y z, {g1.NUM_JOINTS} joints), or (T, {width + 7}) with an object pose")
    return MotionClip.from_joint_trajectory(fps or stored_fps or HOLOSOMA_FPS, qpos[:, :3], qpos[:, 3:7],
                                            qpos[:, 7:width], source=path.name, tags=("holosoma",))


class _ArraysOnly(pickle.Unpickler):
    """Builds numpy arrays, numpy scalars and plain Python containers; refuses anything else."""

    ALLOWED = frozenset({("numpy", "ndarray"), ("numpy", "dtype"), ("numpy.core.multiarray", "_reconstruct"),
               ("numpy._core.multiarray", "_reconstruct"), ("numpy.core.multiarray", "scalar"),
               ("numpy._core.multiarray", "scalar"), ("builtins", "dict"), ("builtins", "list"),
               ("builtins", "tuple"), ("collections", "OrderedDict")})

    def find_class(self, module: str, name: str):
        if (module, name) in self.ALLOWED:
            return super().find_class(module, name)
        raise pickle.UnpicklingError(f"refusing to load {module}.{name} (only numpy arrays are read)")


def read_gmr_pkl(path: str | Path, fps: float | None = None) -> MotionClip:
    path = Path(path)
    try:
        with path.open("rb") as f:
            data = _ArraysOnly(f).load()
    except (OSError, pickle.UnpicklingError, EOFError, AttributeError, ValueError) as exc:
        raise MotionFormatError(f"{path}: not a readable GMR motion pickle ({exc})") from None
    needed = ("root_pos", "root_rot", "dof_pos")
    if not isinstance(data, dict) or any(k not in data for k in needed):
        have = sorted(data) if isinstance(data, dict) else type(data).__name__
        raise MotionFormatError(f"{path}: a GMR motion pickle is a dict with {list(needed)} and fps; got {have}")
    root = np.asarray(data["root_pos"], dtype=float)
    quat_xyzw = np.asarray(data["root_rot"], dtype=float)
    joints = np.asarray(data["dof_pos"], dtype=float)
    t = root.shape[0] if root.ndim == 2 else -1
    if root.shape != (t, 3) or quat_xyzw.shape != (t, 4) or joints.shape != (t, g1.NUM_JOINTS):
        raise MotionFormatError(f"{path}: root_pos {root.shape}, root_rot {quat_xyzw.shape}, dof_pos {joints.shape}; "
                                f"expected (T, 3), (T, 4) and (T, {g1.NUM_JOINTS}) (a 29-DoF G1 motion)")
    rate = fps or (float(data["fps"]) if "fps" in data else None)
    if not rate:
        raise MotionFormatError(f"{path}: the pickle stores no fps; give the frame rate")
    return MotionClip.from_joint_trajectory(rate, root, quat_xyzw[:, [3, 0, 1, 2]], joints, source=path.name,
                                            tags=("gmr",))
