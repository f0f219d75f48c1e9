"""Baselines of the in-betweening harness.

Interpolation (Harvey et al. 2020's baseline): pelvis position linear, pelvis orientation by
slerp, every joint slerped - for the G1's 1-DoF joints, linear in angle.

Motion matching (the classic form that learned motion matching (Holden et al. 2020) starts from):
a feature database over every training window of the same gap length - the pose and velocity
of its first frame (matching the last context frame) and the pose and root placement of its
last frame (matching the target) - searched with a KD-tree. The best window is placed in the
canonical frame and its start and end offsets to the context and the target are blended out
linearly across the gap, so it starts where the context ends and lands on the target, as any
game engine would splice it.
"""

from __future__ import annotations

import numpy as np

from g1_control import rotations as quat
from g1_control.generator import features as F
from g1_control.generator.inbetween import Inbetweener, fill_target, interpolate


class InterpolationInbetweener(Inbetweener):
    name = "interpolation"

    def infill(self, context, target, target_mask, gap, style):
        self.check(context, target, target_mask, gap, style)
        last = context[:, -1]
        full = fill_target(last, target, target_mask, gap)
        out = interpolate(last, full, gap)
        q0 = quat.from_matrix(F.rot6d_to_matrix(last[:, F.ROOT_ROT]))
        q1 = quat.from_matrix(F.rot6d_to_matrix(full[:, F.ROOT_ROT]))
        alpha = np.arange(1, gap + 1) / (gap + 1)
        rot = quat.to_matrix(quat.slerp(q0[:, None], q1[:, None], alpha[None, :]))
        out[..., 3:6], out[..., 6:9] = rot[..., :, 0], rot[..., :, 1]
        return F.fix_effectors(out)


def _match_features(start: np.ndarray, prev: np.ndarray, end: np.ndarray) -> np.ndarray:
    """Search features: start pose, start root velocity, end root placement, end pose (canonical)."""
    vel = start[..., F.ROOT_POS] - prev[..., F.ROOT_POS]
    return np.concatenate([start[..., F.JOINTS], start[..., 2:3], vel * 10.0, end[..., F.ROOT],
                           end[..., F.JOINTS], end[..., F.EFFECTORS]], axis=-1)


class MotionMatchingInbetweener(Inbetweener):
    name = "motion_matching"

    def __init__(self, clips_features: list[np.ndarray]):
        self.clips = [np.asarray(c) for c in clips_features]
        self._db: dict[int, tuple] = {}

    def _database(self, gap: int):
        if gap in self._db:
            return self._db[gap]
        from scipy.spatial import cKDTree

        keys: list[np.ndarray] = []
        feat_rows: list[np.ndarray] = []
        for c, clip in enumerate(self.clips):
            n = clip.shape[0] - (gap + 2)
            if n <= 0:
                continue
            starts = np.arange(n)
            # prev, start, end frames only, canonical w.r.t. the start (it plays the last context frame)
            three = F.canonicalize(clip[starts[:, None] + np.array([0, 1, gap + 2])[None, :]], 1)
            feat_rows.append(_match_features(three[:, 1], three[:, 0], three[:, 2]))
            keys.append(np.stack([np.full(n, c), starts], axis=1))
        feats = np.concatenate(feat_rows)
        scale = feats.std(axis=0) + 1e-3
        self._db[gap] = (cKDTree(feats / scale), scale, np.concatenate(keys), feats.mean(axis=0))
        return self._db[gap]

    def segment(self, key: np.ndarray, gap: int) -> np.ndarray:
        """The (gap + 3)-frame window `key` = (clip, start), canonical w.r.t. its second frame."""
        return F.canonicalize(self.clips[key[0]][key[1]:key[1] + gap + 3], 1)

    def infill(self, context, target, target_mask, gap, style):
        self.check(context, target, target_mask, gap, style)
        tree, scale, keys, mean = self._database(gap)
        last = context[:, -1]
        full = fill_target(last, target, target_mask, gap)
        query = _match_features(last, context[:, -2], full)
        # Target features that are not given must not steer the search: they take the database
        # mean, the least informative value.
        given = np.concatenate([np.ones(29 + 1 + 3, dtype=bool)[None].repeat(len(last), 0),
                                target_mask[:, F.ROOT], target_mask[:, F.JOINTS], target_mask[:, F.EFFECTORS]], axis=1)
        query = np.where(given, query, mean)
        _, best = tree.query(query / scale)
        seg = np.stack([self.segment(keys[i], gap) for i in np.atleast_1d(best)])  # (B, gap + 3, D)
        start_off = last - seg[:, 1]
        end_off = full - seg[:, -1]
        alpha = (np.arange(1, gap + 1) / (gap + 1))[None, :, None]
        # windows hold gap + 3 frames: prev, start, gap frames, end
        out = seg[:, 2:2 + gap] + (1 - alpha) * start_off[:, None] + alpha * end_off[:, None]
        rot = F.rot6d_to_matrix(out[..., F.ROOT_ROT])
        out[..., 3:6], out[..., 6:9] = rot[..., :, 0], rot[..., :, 1]
        return F.fix_effectors(out)
