"""The generator's frame representation, in a canonical frame per plan.

Every plan (and every training window) is expressed relative to the last context frame: its
pelvis projected onto the ground at the origin, its heading along +x. That makes the model
invariant to where the robot is and which way it faces, so it never sees world coordinates that
grow without bound over a long session.

Frame feature vector (D = 67), all in the canonical frame, the same layout for every skeleton
(skeleton.py; a slot a variant lacks holds 0):
    [0:3]    pelvis position, m
    [3:9]    pelvis rotation, first two columns of its rotation matrix (continuous 6D form)
    [9:38]   29 body joint angles, rad, g1.JOINT_NAMES order
    [38:53]  effector positions, m: left hand, right hand, left foot, right foot (wrist-yaw and
             ankle-roll link origins), head (the head link's centre of mass, on the torso)
    [53:67]  14 Dex3 finger joint angles, rad, skeleton.FINGER_JOINTS order
"""

from __future__ import annotations

import numpy as np

from g1_control.robot import g1
from g1_control.rotations import rot_z, yaw_of_matrix

ROOT_POS = slice(0, 3)
ROOT_ROT = slice(3, 9)
ROOT = slice(0, 9)
JOINTS = slice(9, 38)
EFFECTORS = slice(38, 53)
FINGERS = slice(53, 67)
DIM = 67
HEAD = "head"
EFFECTOR_BODIES = g1.HAND_BODIES + g1.FOOT_BODIES + (HEAD,)
"""Effector names (goal frames): wrist-yaw links, ankle-roll links, and the head point."""
NUM_EFFECTORS = len(EFFECTOR_BODIES)
JOINT_SLOTS = np.r_[9:38, 53:67]
"""Feature index of each joint slot (skeleton.SLOT_NAMES order)."""
HEIGHT_ONLY = np.zeros(DIM, dtype=bool)
HEIGHT_ONLY[2] = True


def effector_slice(name: str) -> slice:
    """Feature columns of an effector's position."""
    k = EFFECTOR_BODIES.index(name)
    return slice(38 + 3 * k, 41 + 3 * k)


def present_mask(skeleton_present: np.ndarray) -> np.ndarray:
    """(DIM,) bool: which features exist on a skeleton (root and effectors always)."""
    out = np.ones(DIM, dtype=bool)
    out[JOINT_SLOTS] = skeleton_present
    return out


def effectors_from_bodies(pos: np.ndarray, rot: np.ndarray, body_names: tuple[str, ...]) -> np.ndarray:
    """Effector positions (..., NUM_EFFECTORS, 3) from body positions/rotations (..., B, 3[, 3])."""
    from g1_control.generator.fk import head_offset

    ends = pos[..., [body_names.index(b) for b in EFFECTOR_BODIES[:4]], :]
    t = body_names.index(g1.TORSO_BODY)
    head = pos[..., t, :] + np.einsum("...ij,j->...i", rot[..., t, :, :], head_offset())
    return np.concatenate([ends, head[..., None, :]], axis=-2)

def _gram_schmidt(r6: np.ndarray) -> tuple[np.ndarray, ...]:
    """The two orthonormal columns (x0, x1, x2, y0, y1, y2) of 6D rotations (..., 6). Written out
    (no np.cross / np.linalg.norm / np.stack): this runs several times per replan."""
    a0, a1, a2, b0, b1, b2 = (r6[..., i] for i in range(6))
    na = np.sqrt(a0 * a0 + a1 * a1 + a2 * a2) + 1e-12
    x0, x1, x2 = a0 / na, a1 / na, a2 / na
    d = x0 * b0 + x1 * b1 + x2 * b2
    b0, b1, b2 = b0 - d * x0, b1 - d * x1, b2 - d * x2
    nb = np.sqrt(b0 * b0 + b1 * b1 + b2 * b2) + 1e-12
    return x0, x1, x2, b0 / nb, b1 / nb, b2 / nb


def rot6d_to_matrix(r6: np.ndarray) -> np.ndarray:
    """Gram-Schmidt of the two stored columns -> (..., 3, 3)."""
    x0, x1, x2, y0, y1, y2 = _gram_schmidt(r6)
    out = np.empty(r6.shape[:-1] + (3, 3))
    out[..., 0, 0], out[..., 1, 0], out[..., 2, 0] = x0, x1, x2
    out[..., 0, 1], out[..., 1, 1], out[..., 2, 1] = y0, y1, y2
    out[..., 0, 2], out[..., 1, 2], out[..., 2, 2] = x1 * y2 - x2 * y1, x2 * y0 - x0 * y2, x0 * y1 - x1 * y0
    return out


def orthonormalize_rot6d(frames: np.ndarray) -> None:
    """Re-orthonormalize the pelvis 6D columns of feature frames (..., D) in place."""
    x0, x1, x2, y0, y1, y2 = _gram_schmidt(frames[..., ROOT_ROT])
    frames[..., 3], frames[..., 4], frames[..., 5] = x0, x1, x2
    frames[..., 6], frames[..., 7], frames[..., 8] = y0, y1, y2


def heading(frames: np.ndarray) -> np.ndarray:
    """Yaw of the pelvis x axis of feature frames (...,)."""
    return np.arctan2(frames[..., 4], frames[..., 3])


def world_features(root_pos: np.ndarray, root_rot: np.ndarray, joints: np.ndarray,
                   effectors: np.ndarray, fingers: np.ndarray | None = None) -> np.ndarray:
    """(T, 3), (T, 3, 3), (T, 29), (T, NUM_EFFECTORS, 3)[, (T, 14)] world quantities -> (T, D)
    features (world frame)."""
    t = root_pos.shape[0]
    out = np.zeros((t, DIM))
    out[:, ROOT_POS] = root_pos
    out[:, ROOT_ROT] = np.concatenate([root_rot[:, :, 0], root_rot[:, :, 1]], axis=-1)
    out[:, JOINTS] = joints
    out[:, EFFECTORS] = effectors.reshape(t, 3 * NUM_EFFECTORS)
    if fingers is not None:
        out[:, FINGERS] = fingers
    return out


def clip_features(clip, fingers: np.ndarray | None = None) -> np.ndarray:
    """World-frame features of a MotionClip (+ its finger angles, for the G1 with hands), (T, D)."""
    from g1_control import rotations as quat

    eff = effectors_from_bodies(clip.body_pos_w_m, quat.to_matrix(clip.body_quat_wxyz), clip.body_names)
    return world_features(clip.root_pos_w_m, quat.to_matrix(clip.root_quat_wxyz), clip.joint_pos_rad, eff, fingers)


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
    eff = features[..., EFFECTORS].reshape(features.shape[:-1] + (NUM_EFFECTORS, 3))
    r4 = r[..., None, :, :]
    o4 = o[..., None, :]
    eff = (np.einsum("...ij,...j->...i", r4, eff - o4) if not inverse else np.einsum("...ij,...j->...i", r4, eff) + o4)
    out[..., EFFECTORS] = eff.reshape(features.shape[:-1] + (3 * NUM_EFFECTORS,))
    return out


_PLANAR_X = np.r_[0, 3, 6, 38:53:3]
_PLANAR_Y = _PLANAR_X + 1


def transform_one(features: np.ndarray, origin_xy: np.ndarray, yaw: float, inverse: bool = False) -> np.ndarray:
    """transform() for one frame set (T, D) and one planar frame, written for the per-replan path
    (a 2x2 rotation of the x/y columns; transform() costs ~5x more for this case)."""
    c, s = np.cos(yaw), np.sin(yaw)
    out = features.copy()
    xs, ys = _PLANAR_X, _PLANAR_Y
    x, y = features[..., xs], features[..., ys]
    if inverse:
        out[..., xs] = c * x - s * y
        out[..., ys] = s * x + c * y
        out[..., 0] += origin_xy[0]
        out[..., 1] += origin_xy[1]
        out[..., 38:53:3] += origin_xy[0]
        out[..., 39:53:3] += origin_xy[1]
    else:
        x = x.copy()
        y = y.copy()
        x[..., 0] -= origin_xy[0]
        y[..., 0] -= origin_xy[1]
        x[..., 3:] -= origin_xy[0]
        y[..., 3:] -= origin_xy[1]
        out[..., xs] = c * x + s * y
        out[..., ys] = -s * x + c * y
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
    pos, rot = bodies_of(features)
    from g1_control.motion.kinematics import default_body_names

    out = features.copy()
    eff = effectors_from_bodies(pos, rot, default_body_names())
    out[..., EFFECTORS] = eff.reshape(features.shape[:-1] + (3 * NUM_EFFECTORS,))
    return out


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
