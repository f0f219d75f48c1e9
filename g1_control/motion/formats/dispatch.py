"""Pick a reader or writer by file extension."""

from __future__ import annotations

from pathlib import Path

from g1_control.motion.clip import MotionClip
from g1_control.motion.exceptions import MotionFormatError
from g1_control.motion.human import HumanMotion

HUMAN_EXTENSIONS = (".npy", ".pt", ".bvh")
ROBOT_EXTENSIONS = (".csv", ".npz", ".pkl")


def load_motion(path: str | Path, joint_names: tuple[str, ...] | None = None, fps: float | None = None,
                height_m: float | None = None) -> HumanMotion | MotionClip:
    """A HumanMotion (.npy, .pt, .bvh) or a MotionClip (.csv: Unitree G1 CSV; .npz: motion library /
    BeyondMimic / mjlab, or a holosoma result with qpos; .pkl: a GMR motion) from `path`."""
    from g1_control.motion.formats import bvh, clip_npz, g1_csv, joint_positions, robot_qpos

    path = Path(path)
    if not path.is_file():
        raise MotionFormatError(f"{path}: no such file")
    ext = path.suffix.lower()
    if ext == ".npy":
        kwargs = {"fps": fps} if fps else {}
        return joint_positions.read_npy(path, joint_names, height_m=height_m, **kwargs)
    if ext == ".pt":
        return joint_positions.read_omomo_pt(path, height_m)
    if ext == ".bvh":
        return bvh.read_bvh(path, height_m=height_m)
    if ext == ".csv":
        return g1_csv.read_g1_csv(path, fps or g1_csv.DEFAULT_FPS)
    if ext == ".npz":
        with clip_npz.open_npz(path) as data:
            keys = list(data.files)
        if robot_qpos.is_holosoma_npz(keys):
            return robot_qpos.read_holosoma_npz(path, fps)
        return clip_npz.read_clip_npz(path)
    if ext == ".pkl":
        return robot_qpos.read_gmr_pkl(path, fps)
    raise MotionFormatError(f"{path}: unknown motion file type '{ext}'; known: "
                            f"{', '.join(HUMAN_EXTENSIONS + ROBOT_EXTENSIONS)}")


def load_human_motion(path: str | Path, joint_names: tuple[str, ...] | None = None, fps: float | None = None,
                      height_m: float | None = None) -> HumanMotion:
    """`load_motion` for motion capture to retarget: a G1 clip (.csv, .npz) is refused."""
    motion = load_motion(path, joint_names, fps, height_m)
    if not isinstance(motion, HumanMotion):
        raise MotionFormatError(f"{path}: a G1 clip, not human motion; expected one of {', '.join(HUMAN_EXTENSIONS)}")
    return motion


def save_clip(clip: MotionClip, path: str | Path) -> None:
    from g1_control.motion.formats import clip_npz, g1_csv

    ext = Path(path).suffix.lower()
    if ext == ".npz":
        clip_npz.write_clip_npz(clip, path)
    elif ext == ".csv":
        g1_csv.write_g1_csv(clip, path)
    else:
        raise MotionFormatError(f"{path}: can write .npz (motion library) or .csv (Unitree G1 CSV), not '{ext}'")
