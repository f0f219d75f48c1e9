"""The in-betweening benchmark on held-out clips, after Harvey et al. 2020 ("Robust motion
in-betweening", the protocol COMET and later work report):

- windows of 10 context frames, a gap of N frames (15 and 30 here), and 1 target keyframe,
  taken every 20 frames from every held-out clip, in the canonical frame of the last context frame;
- L2Q: mean over windows and gap frames of the L2 norm of the difference of the global
  quaternions of all 30 bodies (concatenated; each predicted quaternion takes the sign of its
  ground truth, since q and -q are the same rotation);
- L2P: the same on global body positions, each coordinate normalized by the mean and standard
  deviation of the training windows (Harvey et al. normalize by training statistics);
- NPSS (Gopalakrishnan et al. 2019): earth mover's distance between the normalized power spectra
  of predicted and true quaternion channels over the gap, weighted by each channel's true power.
Plus motion quality: foot skating (horizontal ankle speed while the ankle is at stance height)
and ground penetration, for generated and for true frames.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from g1_control import rotations as quat
from g1_control.generator import features as F
from g1_control.generator.inbetween import CONTEXT_FRAMES, Inbetweener
from g1_control.robot import g1

WINDOW_STRIDE = 20
STANCE_ANKLE_Z_M = 0.034
"""The ankle-roll link origin's height over the floor when the sole is flat on it."""
CONTACT_BAND_M = 0.025
"""A foot whose ankle is within this of its standing height is on the ground (stance)."""
PENETRATION_M = 0.02


@dataclass
class Windows:
    gap: int
    frames: np.ndarray
    """(N, C + gap + 1, D) canonical w.r.t. frame C - 1."""
    style: np.ndarray
    """(N,) style ids."""

    @property
    def context(self) -> np.ndarray:
        return self.frames[:, :CONTEXT_FRAMES]

    @property
    def truth(self) -> np.ndarray:
        return self.frames[:, CONTEXT_FRAMES:-1]

    @property
    def target(self) -> np.ndarray:
        return self.frames[:, -1]


def make_windows(clip_feats: list[np.ndarray], styles: list[int], gap: int, stride: int = WINDOW_STRIDE) -> Windows:
    length = CONTEXT_FRAMES + gap + 1
    out, sty = [], []
    for feats, s in zip(clip_feats, styles):
        starts = np.arange(0, feats.shape[0] - length + 1, stride)
        if starts.size == 0:
            continue
        out.append(F.canonicalize(feats[starts[:, None] + np.arange(length)[None, :]], CONTEXT_FRAMES - 1))
        sty.append(np.full(starts.size, s))
    return Windows(gap, np.concatenate(out), np.concatenate(sty))


@dataclass
class PositionStats:
    mean: np.ndarray
    std: np.ndarray

    @classmethod
    def from_windows(cls, windows: Windows) -> PositionStats:
        pos, _ = F.bodies_of(windows.truth)
        flat = pos.reshape(-1, pos.shape[-2], 3)
        return cls(flat.mean(axis=0), flat.std(axis=0) + 1e-6)


def _global(feats: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    pos, rot = F.bodies_of(feats)
    return pos, quat.from_matrix(rot)


def npss(pred: np.ndarray, true: np.ndarray) -> float:
    """pred, true (N, T, C) -> NPSS averaged over windows."""
    pp = np.abs(np.fft.rfft(pred, axis=1)) ** 2
    tp = np.abs(np.fft.rfft(true, axis=1)) ** 2
    tot_true = tp.sum(axis=1, keepdims=True)
    pn = pp / np.maximum(pp.sum(axis=1, keepdims=True), 1e-12)
    tn = tp / np.maximum(tot_true, 1e-12)
    emd = np.abs(np.cumsum(pn, axis=1) - np.cumsum(tn, axis=1)).sum(axis=1)  # (N, C)
    weights = tot_true[:, 0]
    return float(np.mean((emd * weights).sum(axis=1) / np.maximum(weights.sum(axis=1), 1e-12)))


def foot_quality(feats: np.ndarray, fps: float) -> tuple[float, float]:
    """(skating: mean horizontal ankle speed in m/s while the ankle is at stance height,
    penetration: fraction of frames whose lowest ankle is >2 cm under stance height)."""
    pos, _ = F.bodies_of(feats)
    from g1_control.motion.kinematics import default_body_names

    names = default_body_names()
    feet = pos[..., [names.index(b) for b in g1.FOOT_BODIES], :]  # (N, T, 2, 3)
    speed = np.linalg.norm(np.diff(feet[..., :2], axis=1), axis=-1) * fps
    contact = feet[:, 1:, :, 2] < STANCE_ANKLE_Z_M + CONTACT_BAND_M
    skate = float(speed[contact].mean()) if contact.any() else 0.0
    pen = float((feet[..., 2].min(axis=-1) < STANCE_ANKLE_Z_M - PENETRATION_M).mean())
    return skate, pen


def skate_on_true_stance(feats: np.ndarray, truth: np.ndarray, fps: float) -> float:
    """Foot skating judged on the ground truth's stance frames instead of the prediction's own: mean
    horizontal ankle speed (m/s) of the predicted feet where the true ankle is at stance height (a
    second reading of foot_quality's skating that a method cannot lower by lifting its feet)."""
    pos, _ = F.bodies_of(feats)
    true_pos, _ = F.bodies_of(truth)
    from g1_control.motion.kinematics import default_body_names

    names = default_body_names()
    idx = [names.index(b) for b in g1.FOOT_BODIES]
    speed = np.linalg.norm(np.diff(pos[..., idx, :2], axis=1), axis=-1) * fps
    contact = true_pos[:, 1:, idx, 2] < STANCE_ANKLE_Z_M + CONTACT_BAND_M
    return float(speed[contact].mean()) if contact.any() else 0.0


@dataclass
class Scores:
    method: str
    gap: int
    l2p: float
    l2q: float
    npss: float
    skate_mps: float
    penetration: float


def predict(method: Inbetweener, windows: Windows, batch: int = 256) -> np.ndarray:
    """The method's gap frames (N, gap, D) for every window, full target keyframes, in batches."""
    mask = np.ones((len(windows.frames), F.DIM), dtype=bool)
    preds = []
    for a in range(0, len(windows.frames), batch):
        b = slice(a, a + batch)
        preds.append(method.infill(windows.context[b], windows.target[b], mask[b], windows.gap, windows.style[b]))
    return np.concatenate(preds)


def score(method: Inbetweener, windows: Windows, stats: PositionStats, fps: float = 30.0,
          batch: int = 256) -> Scores:
    return score_predictions(method.name, predict(method, windows, batch), windows, stats, fps)


def score_predictions(name: str, pred: np.ndarray, windows: Windows, stats: PositionStats, fps: float) -> Scores:
    p_pos, p_q = _global(pred)
    t_pos, t_q = _global(windows.truth)
    p_q = p_q * np.where(np.sum(p_q * t_q, axis=-1, keepdims=True) < 0, -1.0, 1.0)
    n, t = pred.shape[:2]
    l2q = np.linalg.norm((p_q - t_q).reshape(n, t, -1), axis=-1).mean()
    l2p = np.linalg.norm(((p_pos - t_pos) / stats.std).reshape(n, t, -1), axis=-1).mean()
    skate, pen = foot_quality(pred, fps)
    return Scores(name, windows.gap, float(l2p), float(l2q), npss(p_q.reshape(n, t, -1), t_q.reshape(n, t, -1)),
                  skate, pen)
