"""Learned motion matching (Holden, Kanoun, Perepichka, Popa 2020) as an Inbetweener.

Motion matching keeps a database of matching features x (what the search compares) and poses y
(what it plays) for every library frame. Learned motion matching replaces the database by three
small networks (training/lmm.py):
- decompressor D(x, z) -> y, with z a learned latent of the pose (a compressor, used only in
  training, makes z from y);
- stepper S(x_t, z_t) -> (x_{t+1}, z_{t+1}) - playing the database forward;
- projector P(query) -> (x, z) of the best-matching database frame - the search itself.
At run time a plan is: query -> P -> S, S, ... -> D on every frame, one ONNX graph (lmm.onnx),
numpy around it. Memory is the networks' weights instead of the database.

Matching features x (Holden's set, in the frame's own canonical frame; 30 fps):
    feet positions (6) and velocities (6), pelvis velocity (3), the root's future positions at
    +10/+20/+30 frames (6) and facing directions (6), hand positions (6), and the style one-hot
    (11) - so the same styles drive it as every other method.
Pose y: pelvis height (1), pelvis rotation 6D relative to the heading (6), the 43 joint slots, the
5 effectors (15), the pelvis velocity (3) and yaw rate (1), so the root path is integrated.

As an in-betweener the query comes from the context's last frame and a root path to the target
keyframe (linear in position, the heading eased along), and the played frames are spliced like
the motion-matching baseline's: their offsets to the context and to the given target features
are blended out across the gap.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from g1_control.generator import features as F
from g1_control.generator.inbetween import Inbetweener, fill_target
from g1_control.generator.learned import model_info
from g1_control.generator.styles import STYLES
from g1_control.rotations import wrap_angle

SHIPPED_LMM_DIR = Path(__file__).resolve().parents[1] / "policies" / "generator" / "lmm"
FPS = 30.0
TRAJ_OFFSETS = (10, 20, 30)
X_DIM = 6 + 6 + 3 + 6 + 6 + 6 + len(STYLES)
Y_DIM = 1 + 6 + 43 + 15 + 3 + 1
MAX_STEPS = 32
"""Frames the exported rollout plays (>= MAX_GAP + 2)."""
FOOT_COLS = np.r_[F.effector_slice("left_ankle_roll_link"), F.effector_slice("right_ankle_roll_link")]
HAND_COLS = np.r_[F.effector_slice("left_wrist_yaw_link"), F.effector_slice("right_wrist_yaw_link")]
X_GROUPS = {"feet_pos": slice(0, 6), "feet_vel": slice(6, 12), "root_vel": slice(12, 15), "traj_pos": slice(15, 21),
            "traj_dir": slice(21, 27), "hands": slice(27, 33), "style": slice(33, X_DIM)}
X_WEIGHTS = {"feet_pos": 0.75, "feet_vel": 1.0, "root_vel": 1.0, "traj_pos": 1.0, "traj_dir": 1.5, "hands": 0.75,
             "style": 2.0}
"""Search weights per group (applied on top of per-dimension standardisation, as Holden et al.)."""


def _yaw(frames: np.ndarray) -> np.ndarray:
    return F.yaw_of_matrix(F.rot6d_to_matrix(frames[..., F.ROOT_ROT]))


def _rot2(v: np.ndarray, yaw: np.ndarray) -> np.ndarray:
    """Rotate (..., 2) vectors by -yaw (world -> heading frame)."""
    c, s = np.cos(yaw)[..., None], np.sin(yaw)[..., None]
    return np.concatenate([c * v[..., :1] + s * v[..., 1:2], -s * v[..., :1] + c * v[..., 1:2]], axis=-1)


def _local_points(points: np.ndarray, origin: np.ndarray, yaw: np.ndarray) -> np.ndarray:
    """(..., K, 3) world points -> heading frame at (origin (..., 3) xy, yaw)."""
    d = points.copy()
    d[..., :2] -= origin[..., None, :2]
    d[..., :2] = _rot2(d[..., :2], yaw[..., None])
    return d


def clip_database(feats: np.ndarray, style: int) -> tuple[np.ndarray, np.ndarray]:
    """World features of one clip (T, D) -> matching features X (N, X_DIM) and poses Y (N, Y_DIM) of
    its frames 1 .. T-31 (each needs a previous frame and 30 future ones)."""
    t = feats.shape[0]
    idx = np.arange(1, t - TRAJ_OFFSETS[-1])
    if idx.size == 0:
        return np.zeros((0, X_DIM)), np.zeros((0, Y_DIM))
    yaw = _yaw(feats)
    cur, prev, nxt = feats[idx], feats[idx - 1], feats[idx + 1]
    y0 = yaw[idx]
    origin = cur[:, F.ROOT_POS]
    x = np.zeros((len(idx), X_DIM))
    feet = cur[:, FOOT_COLS].reshape(-1, 2, 3)
    x[:, 0:6] = _local_points(feet, origin, y0).reshape(-1, 6)
    dv = (feet - prev[:, FOOT_COLS].reshape(-1, 2, 3)) * FPS
    dv[..., :2] = _rot2(dv[..., :2], y0[:, None])
    x[:, 6:12] = dv.reshape(-1, 6)
    rv = (cur[:, F.ROOT_POS] - prev[:, F.ROOT_POS]) * FPS
    rv[:, :2] = _rot2(rv[:, :2], y0)
    x[:, 12:15] = rv
    for k, off in enumerate(TRAJ_OFFSETS):
        fut = feats[idx + off]
        x[:, 15 + 2 * k:17 + 2 * k] = _rot2(fut[:, 0:2] - origin[:, :2], y0)
        dyaw = yaw[idx + off] - y0
        x[:, 21 + 2 * k:23 + 2 * k] = np.stack([np.cos(dyaw), np.sin(dyaw)], axis=1)
    x[:, 27:33] = _local_points(cur[:, HAND_COLS].reshape(-1, 2, 3), origin, y0).reshape(-1, 6)
    x[:, 33 + style] = 1.0
    return x, pose_features(cur, nxt)


def pose_features(cur: np.ndarray, nxt: np.ndarray) -> np.ndarray:
    """Frames (N, D) and their successors -> poses y (N, Y_DIM) in each frame's heading frame."""
    rot = F.rot6d_to_matrix(cur[:, F.ROOT_ROT])
    yaw = F.yaw_of_matrix(rot)
    n = cur.shape[0]
    y = np.zeros((n, Y_DIM))
    y[:, 0] = cur[:, 2]
    local = np.einsum("nji,njk->nik", F.rot_z(yaw), rot)
    y[:, 1:4], y[:, 4:7] = local[:, :, 0], local[:, :, 1]
    y[:, 7:50] = cur[:, F.JOINT_SLOTS]
    eff = cur[:, F.EFFECTORS].reshape(n, F.NUM_EFFECTORS, 3)
    y[:, 50:65] = _local_points(eff, cur[:, F.ROOT_POS], yaw).reshape(n, 15)
    v = (nxt[:, F.ROOT_POS] - cur[:, F.ROOT_POS]) * FPS
    v[:, :2] = _rot2(v[:, :2], yaw)
    y[:, 65:68] = v
    y[:, 68] = wrap_angle(_yaw(nxt) - yaw) * FPS
    return y


def query_features(context: np.ndarray, target_full: np.ndarray, target_mask: np.ndarray, gap: int,
                   style: np.ndarray) -> np.ndarray:
    """Canonical context (B, C, D) (last frame at the origin facing +x) and the target -> queries
    (B, X_DIM): the last frame's feet, velocities and hands, and the root path toward the target
    (held at the target past the gap). Unknown styles (id len(STYLES)) leave the style block 0."""
    b = context.shape[0]
    cur, prev = context[:, -1], context[:, -2]
    zero = np.zeros(b)
    q = np.zeros((b, X_DIM))
    y0 = _yaw(cur)
    q[:, 0:6] = _local_points(cur[:, FOOT_COLS].reshape(b, 2, 3), cur[:, F.ROOT_POS], y0).reshape(b, 6)
    dv = (cur[:, FOOT_COLS] - prev[:, FOOT_COLS]).reshape(b, 2, 3) * FPS
    dv[..., :2] = _rot2(dv[..., :2], y0[:, None])
    q[:, 6:12] = dv.reshape(b, 6)
    rv = (cur[:, F.ROOT_POS] - prev[:, F.ROOT_POS]) * FPS
    rv[:, :2] = _rot2(rv[:, :2], y0)
    q[:, 12:15] = rv
    root_given = target_mask[:, 0] & target_mask[:, 1]
    end_xy = np.where(root_given[:, None], target_full[:, 0:2], cur[:, 0:2])
    end_yaw = np.where(target_mask[:, 3], _yaw(target_full), y0)
    dyaw_end = wrap_angle(end_yaw - y0)
    for k, off in enumerate(TRAJ_OFFSETS):
        a = min(1.0, off / (gap + 1))
        p = cur[:, 0:2] + a * (end_xy - cur[:, 0:2])
        q[:, 15 + 2 * k:17 + 2 * k] = _rot2(p - cur[:, 0:2], y0)
        ease = a * a * (3 - 2 * a)
        q[:, 21 + 2 * k:23 + 2 * k] = np.stack([np.cos(zero + ease * dyaw_end), np.sin(zero + ease * dyaw_end)], 1)
    q[:, 27:33] = _local_points(cur[:, HAND_COLS].reshape(b, 2, 3), cur[:, F.ROOT_POS], y0).reshape(b, 6)
    known = np.asarray(style) < len(STYLES)
    q[np.flatnonzero(known), 33 + np.asarray(style)[known]] = 1.0
    return q


def frames_from_poses(y: np.ndarray, start_xy: np.ndarray, start_yaw: np.ndarray) -> np.ndarray:
    """Played poses (B, T, Y_DIM) -> canonical features (B, T, D), the root integrated from the first
    pose's placement (start_xy (B, 2), start_yaw (B,))."""
    b, t, _ = y.shape
    yaw = start_yaw[:, None] + np.concatenate([np.zeros((b, 1)), np.cumsum(y[:, :-1, 68], axis=1) / FPS], axis=1)
    c, s = np.cos(yaw), np.sin(yaw)
    vx, vy = y[..., 65], y[..., 66]
    wx, wy = c * vx - s * vy, s * vx + c * vy
    xy = start_xy[:, None, :] + np.concatenate([np.zeros((b, 1, 2)),
                                                np.cumsum(np.stack([wx, wy], -1)[:, :-1], axis=1) / FPS], axis=1)
    out = np.zeros((b, t, F.DIM))
    out[..., 0:2] = xy
    out[..., 2] = y[..., 0]
    rz = F.rot_z(yaw)
    local = F.rot6d_to_matrix(y[..., 1:7])
    rot = rz @ local
    out[..., 3:6], out[..., 6:9] = rot[..., :, 0], rot[..., :, 1]
    out[..., F.JOINT_SLOTS] = y[..., 7:50]
    eff = y[..., 50:65].reshape(b, t, F.NUM_EFFECTORS, 3)
    ex = c[..., None] * eff[..., 0] - s[..., None] * eff[..., 1] + xy[..., None, 0]
    ey = s[..., None] * eff[..., 0] + c[..., None] * eff[..., 1] + xy[..., None, 1]
    out[..., F.EFFECTORS] = np.stack([ex, ey, eff[..., 2]], -1).reshape(b, t, 15)
    return out


class LearnedMotionMatchingInbetweener(Inbetweener):
    name = "learned_motion_matching"

    def __init__(self, folder: str | Path | None = None, threads: int = 1, skeleton: str = "g1_29dof"):
        import onnxruntime as ort

        folder = Path(folder) if folder else SHIPPED_LMM_DIR
        path = folder / "lmm.onnx"
        if not path.is_file():
            raise FileNotFoundError(f"{path}: no learned-motion-matching model; train one with `g1 train lmm`")
        trained = model_info(path).get("skeletons", ["g1_29dof"])
        if skeleton not in trained:
            from g1_control.generator.skeleton import SkeletonError

            raise SkeletonError(f"{folder}: this learned-motion-matching model was trained for {', '.join(trained)}; "
                                f"the robot is {skeleton} (g1 train lmm --skeleton {skeleton})")
        self.skeleton = skeleton
        opts = ort.SessionOptions()
        opts.intra_op_num_threads = threads
        opts.inter_op_num_threads = 1
        self.session = ort.InferenceSession(str(path), opts, providers=["CPUExecutionProvider"])
        self.folder = folder

    def play(self, query: np.ndarray) -> np.ndarray:
        """Queries (B, X_DIM) -> played poses (B, MAX_STEPS, Y_DIM): projected frame first."""
        (y,) = self.session.run(None, {"query": query.astype(np.float32)})
        return y.astype(float)

    def infill(self, context, target, target_mask, gap, style):
        self.check(context, target, target_mask, gap, style)
        last = context[:, -1]
        full = fill_target(last, target, target_mask, gap)
        y = self.play(query_features(context, full, target_mask, gap, np.asarray(style)))[:, :gap + 2]
        frames = frames_from_poses(y, last[:, 0:2], _yaw(last))  # frame 0 = now, gap + 1 = the target's time
        start_off = last - frames[:, 0]
        start_off[:, 0:2] = 0.0  # the root path starts at the context's root already
        end_off = np.where(target_mask, full - frames[:, -1], 0.0)
        # the heading offset as a rotation of the root path about the start, not a 6D blend
        alpha = (np.arange(1, gap + 1) / (gap + 1))[None, :, None]
        out = frames[:, 1:gap + 1] + (1 - alpha) * start_off[:, None] + alpha * end_off[:, None]
        F.orthonormalize_rot6d(out)
        return out
