"""World joint positions (T, J, 3), the holosoma_retargeting demo format.

- `.npy` with (T, J, 3) float positions in m, z-up (the five climbing sequences: 53 joints of the
  holosoma "mocap" skeleton, captured at 120 fps; holosoma downsamples them by 4 to 30 fps). The
  boxes climbed on are the OBJ meshes in `box_models/` beside the file (world coordinates).
- `.pt` (torch) OMOMO / InterMimic sequences: (T, 591) rows at 30 fps whose columns 162:318 hold
  the 52 SMPL-H joint positions (m, z-up). The performer's height comes from `height_dict.pkl`
  next to the file (subject id = file name prefix, e.g. 'sub3').
Facts about the layouts are from holosoma_retargeting's loaders.
"""

from __future__ import annotations

import pickle
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from g1_control.motion.exceptions import MotionFormatError
from g1_control.motion.human import HumanMotion
from g1_control.motion.skeletons import SMPLH, skeleton_for_count

MOCAP_FPS = 120.0
if TYPE_CHECKING:
    from g1_control.motion.objects import ObjectShape, ObjectTrack

OMOMO_FPS = 30.0
OMOMO_JOINT_COLUMNS = slice(162, 162 + 52 * 3)
OMOMO_OBJECT_COLUMNS = slice(318, 325)
"""Object position (x y z) then orientation (qx qy qz qw), world, as holosoma-retargeting's
InterMimic loader reads them (load_intermimic_data)."""


def read_npy(path: str | Path, joint_names: tuple[str, ...] | None = None, fps: float = MOCAP_FPS,
             height_m: float | None = None) -> HumanMotion:
    path = Path(path)
    try:
        pos = np.load(path, allow_pickle=False)
    except Exception as exc:
        raise MotionFormatError(f"{path}: not a readable .npy array ({exc})") from None
    if pos.ndim != 3 or pos.shape[2] != 3:
        raise MotionFormatError(f"{path}: array has shape {pos.shape}; expected (T, J, 3) world joint positions")
    if joint_names is None:
        skeleton = skeleton_for_count(pos.shape[1])
        if skeleton is None:
            raise MotionFormatError(f"{path}: {pos.shape[1]} joints match no known skeleton; pass a joint map")
        joint_names = skeleton.joints
        height_m = height_m or skeleton.default_height_m
    if len(joint_names) != pos.shape[1]:
        raise MotionFormatError(f"{path}: {pos.shape[1]} joints in the file but {len(joint_names)} names in the joint map")
    scene: tuple[ObjectShape, ...] = ()
    if (path.parent / "box_models").is_dir():  # the holosoma climbing layout: the boxes next to the data
        from g1_control.motion.objects import load_scene

        scene = load_scene(path.parent / "box_models")
    return HumanMotion(pos.astype(float), tuple(joint_names), fps, height_m, path.name, scene=scene).validate()


def read_omomo_pt(path: str | Path, height_m: float | None = None) -> HumanMotion:
    import torch

    path = Path(path)
    try:
        raw = torch.load(path, map_location="cpu", weights_only=True)
    except Exception as exc:
        raise MotionFormatError(f"{path}: not a readable torch tensor file ({exc})") from None
    arr = raw.detach().cpu().numpy() if hasattr(raw, "detach") else np.asarray(raw)
    if arr.ndim != 2 or arr.shape[1] < OMOMO_JOINT_COLUMNS.stop:
        raise MotionFormatError(f"{path}: tensor has shape {arr.shape}; expected (T, >= {OMOMO_JOINT_COLUMNS.stop}) "
                                "OMOMO/InterMimic rows")
    pos = arr[:, OMOMO_JOINT_COLUMNS].reshape(-1, 52, 3).astype(float)
    if height_m is None:
        heights = path.parent.parent / "height_dict.pkl"
        heights = heights if heights.is_file() else path.parent / "height_dict.pkl"
        if heights.is_file():
            with heights.open("rb") as fh:
                table = pickle.load(fh)
            subject = path.stem.split("_")[0]
            if subject in table:
                height_m = float(table[subject])
    return HumanMotion(pos, SMPLH.joints, OMOMO_FPS, height_m, path.name, _omomo_object(path, arr)).validate()


def _omomo_object(path: Path, arr: np.ndarray) -> ObjectTrack | None:
    """The manipulated object's track, when the file has the columns and names a known object
    (OMOMO file names read subject_object_take, e.g. sub3_largebox_003)."""
    from g1_control.motion.objects import KNOWN_OBJECTS, ObjectTrack, load_object_shape

    parts = path.stem.split("_")
    name = parts[1] if len(parts) > 2 else ""
    if name not in KNOWN_OBJECTS or arr.shape[1] < OMOMO_OBJECT_COLUMNS.stop:
        return None
    pose = arr[:, OMOMO_OBJECT_COLUMNS].astype(float)
    return ObjectTrack(load_object_shape(name), pose[:, :3], pose[:, [6, 3, 4, 5]])
