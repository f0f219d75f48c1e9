"""The generator's frame representation, in a canonical frame per plan.

Every plan (and every training window) is expressed relative to the last context frame: its
pelvis projected onto the ground at the origin, its heading along +x. That makes the model
invariant to where the robot is and which way it faces, so it never sees world coordinates that
grow without bound over a long session.

Frame feature vector (D = 50), all in the canonical frame:
    [0:3]    pelvis position, m
    [3:9]    pelvis rotation, first two columns of its rotation matrix (continuous 6D form)
    [9:38]   29 joint angles, rad, g1.JOINT_NAMES order
    [38:50]  effector positions, m: left hand, right hand, left foot, right foot
             (wrist-yaw and ankle-roll link origins)
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from g1_control.robot import g1
from g1_control.rotations import rot_z, yaw_of_matrix

ROOT_POS = slice(0, 3)
ROOT_ROT = slice(3, 9)
ROOT = slice(0, 9)
JOINTS = slice(9, 38)
EFFECTORS = slice(38, 50)
DIM = 50
EFFECTOR_BODIES = g1.HAND_BODIES + g1.FOOT_BODIES
HEIGHT_ONLY = np.zeros(DIM, dtype=bool)
HEIGHT_ONLY[2] = True


def effector_indices(body_names: tuple[str, ...]) -> list[int]:
    return [body_names.index(b) for b in EFFECTOR_BODIES]






def rot6d_to_matrix(r6: np.ndarray) -> np.ndarray:
    """Gram-Schmidt of the two stored columns -> (..., 3, 3). Written out (no np.cross /
    np.linalg.norm): this runs several times per replan."""
    a0, a1, a2, b0, b1, b2 = (r6[..., i] for i in range(6))
    na = np.sqrt(a0 * a0 + a1 * a1 + a2 * a2) + 1e-12
    x0, x1, x2 = a0 / na, a1 / na, a2 / na
    d = x0 * b0 + x1 * b1 + x2 * b2
    b0, b1, b2 = b0 - d * x0, b1 - d * x1, b2 - d * x2
    nb = np.sqrt(b0 * b0 + b1 * b1 + b2 * b2) + 1e-12
    y0, y1, y2 = b0 / nb, b1 / nb, b2 / nb
    z0, z1, z2 = x1 * y2 - x2 * y1, x2 * y0 - x0 * y2, x0 * y1 - x1 * y0
    return np.stack([np.stack([x0, y0, z0], -1), np.stack([x1, y1, z1], -1), np.stack([x2, y2, z2], -1)], -2)


def world_features(root_pos: np.ndarray, root_rot: np.ndarray, joints: np.ndarray,
                   effectors: np.ndarray) -> np.ndarray:
    """(T, 3), (T, 3, 3), (T, 29), (T, 4, 3) world quantities -> (T, D) features (world frame)."""
    t = root_pos.shape[0]
    out = np.empty((t, DIM))
    out[:, ROOT_POS] = root_pos
    out[:, ROOT_ROT] = np.concatenate([root_rot[:, :, 0], root_rot[:, :, 1]], axis=-1)
    out[:, JOINTS] = joints
    out[:, EFFECTORS] = effectors.reshape(t, 12)
    return out


def clip_features(clip) -> np.ndarray:
    """World-frame features of a MotionClip, (T, D)."""
    from g1_control import rotations as quat

    eff = clip.body_pos_w_m[:, effector_indices(clip.body_names)]
    return world_features(clip.root_pos_w_m, quat.to_matrix(clip.root_quat_wxyz), clip.joint_pos_rad, eff)


def reference_of(features: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(origin xy (..., 2), yaw (...)) of the canonical frame that features' frames define."""
    rot = rot6d_to_matrix(features[..., ROOT_ROT])
    return features[..., 0:2].copy(), yaw_of_matrix(rot)


def transform(features: np.ndarray, origin_xy: np.ndarray, yaw: np.ndarray, inverse: bool = False) -> np.ndarray:
    """Express features (..., T, D) in the frame at (origin_xy (..., 2), yaw (...)) - or, with
    inverse, bring canonical features back to the world."""
    r = rot_z(-yaw if not inverse else yaw)[..., None, :, :]
    out = features.copy()
    o = np.zeros(origin_xy.shape[:-1] + (3,))
    o[..., :2] = origin_xy
    o = o[..., None, :]

    def pos(p):
        return (np.einsum("...ij,...j->...i", r, p - o) if not inverse
                else np.einsum("...ij,...j->...i", r, p) + o)

    out[..., ROOT_POS] = pos(features[..., ROOT_POS])
    out[..., 3:6] = np.einsum("...ij,...j->...i", r, features[..., 3:6])
    out[..., 6:9] = np.einsum("...ij,...j->...i", r, features[..., 6:9])
    eff = features[..., EFFECTORS].reshape(features.shape[:-1] + (4, 3))
    r4 = r[..., None, :, :]
    o4 = o[..., None, :]
    eff = (np.einsum("...ij,...j->...i", r4, eff - o4) if not inverse else np.einsum("...ij,...j->...i", r4, eff) + o4)
    out[..., EFFECTORS] = eff.reshape(features.shape[:-1] + (12,))
    return out


def canonicalize(window: np.ndarray, ref_index: int) -> np.ndarray:
    """Windows (..., T, D) in the frame of their frame `ref_index`."""
    origin, yaw = reference_of(window[..., ref_index, :])
    return transform(window, origin, yaw)


def bodies_of(features: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Global body positions (..., 30, 3) and rotations (..., 30, 3, 3) of feature frames by FK."""
    from g1_control.generator.fk import fk_numpy

    return fk_numpy(features[..., ROOT_POS], rot6d_to_matrix(features[..., ROOT_ROT]), features[..., JOINTS])


def fix_effectors(features: np.ndarray) -> np.ndarray:
    """Features with the effector block recomputed from root + joints (so generated frames are
    self-consistent)."""
    pos, _ = bodies_of(features)
    from g1_control.motion.kinematics import default_body_names

    out = features.copy()
    idx = effector_indices(default_body_names())
    out[..., EFFECTORS] = pos[..., idx, :].reshape(features.shape[:-1] + (12,))
    return out


def load_split(library_root: str | Path | None, split: str) -> tuple[list[np.ndarray], list[int]]:
    """Features (clip_features) and style ids of the clips of one split ("train", "test") of a
    built motion library (default: the library's default folder)."""
    from g1_control.generator.styles import style_id
    from g1_control.motion.library import MotionLibrary, default_library_dir

    lib = MotionLibrary(library_root or default_library_dir())
    clips = lib.clips(split)
    return [clip_features(c) for c in clips], [style_id(c.style) for c in clips]


def matrix_to_quat(rot: np.ndarray) -> np.ndarray:
    """One rotation matrix -> (w, x, y, z) with w >= 0 (Shepperd's method; scipy's batched
    converter costs ~50x more for a single matrix in the per-tick path)."""
    m = rot
    tr = m[0, 0] + m[1, 1] + m[2, 2]
    if tr > 0:
        s = 2.0 * np.sqrt(tr + 1.0)
        q = np.array([0.25 * s, (m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s])
    elif m[0, 0] > m[1, 1] and m[0, 0] > m[2, 2]:
        s = 2.0 * np.sqrt(1.0 + m[0, 0] - m[1, 1] - m[2, 2])
        q = np.array([(m[2, 1] - m[1, 2]) / s, 0.25 * s, (m[0, 1] + m[1, 0]) / s, (m[0, 2] + m[2, 0]) / s])
    elif m[1, 1] > m[2, 2]:
        s = 2.0 * np.sqrt(1.0 + m[1, 1] - m[0, 0] - m[2, 2])
        q = np.array([(m[0, 2] - m[2, 0]) / s, (m[0, 1] + m[1, 0]) / s, 0.25 * s, (m[1, 2] + m[2, 1]) / s])
    else:
        s = 2.0 * np.sqrt(1.0 + m[2, 2] - m[0, 0] - m[1, 1])
        q = np.array([(m[1, 0] - m[0, 1]) / s, (m[0, 2] + m[2, 0]) / s, (m[1, 2] + m[2, 1]) / s, 0.25 * s])
    q /= np.linalg.norm(q)
    return -q if q[0] < 0 else q
