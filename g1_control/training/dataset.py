"""Training windows for the backbone, sampled on the fly from the library's training clips.

Each sample: C context frames, a gap of G frames (shared by a batch, drawn from [min_gap, 30]),
one target keyframe, canonical w.r.t. the last context frame; plus a random "given" mask on the
target that teaches every conditioning the runtime uses (full pose, root only, root + upper body
(style poses), root + chosen joints/effectors, height-free root) and style dropout so the model
also works with no style.
"""

from __future__ import annotations

import numpy as np

from g1_control.generator import features as F
from g1_control.generator.inbetween import CONTEXT_FRAMES, MAX_GAP, fill_target, interpolate
from g1_control.robot import g1

UPPER = np.zeros(F.DIM, dtype=bool)
UPPER[[9 + j for j in g1.UPPER_BODY_JOINTS]] = True
ROOT_MASK = np.zeros(F.DIM, dtype=bool)
ROOT_MASK[F.ROOT] = True
MASK_KINDS = ("full", "root", "root+upper", "root+chosen")
MASK_PROBS = (0.45, 0.2, 0.2, 0.15)


class WindowSampler:
    def __init__(self, clip_feats: list[np.ndarray], styles: list[int], num_styles: int, seed: int = 0,
                 min_gap: int = 5, style_dropout: float = 0.1):
        self.clips = [c for c in clip_feats if c.shape[0] >= CONTEXT_FRAMES + MAX_GAP + 1]
        self.styles = [s for c, s in zip(clip_feats, styles) if c.shape[0] >= CONTEXT_FRAMES + MAX_GAP + 1]
        if not self.clips:
            raise ValueError(f"no training clip has the {CONTEXT_FRAMES + MAX_GAP + 1} frames a window needs")
        lengths = np.array([c.shape[0] - (CONTEXT_FRAMES + MAX_GAP + 1) + 1 for c in self.clips], dtype=float)
        self.p = lengths / lengths.sum()
        self.rng = np.random.default_rng(seed)
        self.min_gap = min_gap
        self.num_styles = num_styles
        self.style_dropout = style_dropout

    def masks(self, b: int) -> np.ndarray:
        kind = self.rng.choice(len(MASK_KINDS), size=b, p=MASK_PROBS)
        out = np.zeros((b, F.DIM), dtype=bool)
        out[kind == 0] = True
        out[kind == 1] = ROOT_MASK
        out[kind == 2] = ROOT_MASK | UPPER
        chosen = kind == 3
        n = int(chosen.sum())
        if n:
            pick = self.rng.random((n, F.DIM)) < 0.3
            pick[:, F.ROOT] = True
            out[chosen] = pick
        return out

    def sample(self, batch: int, gap: int | None = None) -> dict[str, np.ndarray]:
        gap = gap or int(self.rng.integers(self.min_gap, MAX_GAP + 1))
        length = CONTEXT_FRAMES + gap + 1
        which = self.rng.choice(len(self.clips), size=batch, p=self.p)
        wins = np.empty((batch, length, F.DIM))
        for i, c in enumerate(which):
            start = int(self.rng.integers(0, self.clips[c].shape[0] - length + 1))
            wins[i] = self.clips[c][start:start + length]
        wins = F.canonicalize(wins, CONTEXT_FRAMES - 1)
        style = np.array([self.styles[c] for c in which])
        style[self.rng.random(batch) < self.style_dropout] = self.num_styles  # "unknown"
        mask = self.masks(batch)
        context, target = wins[:, :CONTEXT_FRAMES], wins[:, -1]
        base = interpolate(context[:, -1], fill_target(context[:, -1], target, mask, gap), gap)
        return {"context": context, "target": np.where(mask, target, 0.0), "given": mask.astype(float),
                "base": base, "style": style, "truth": wins[:, CONTEXT_FRAMES:-1], "gap": np.array(gap)}
