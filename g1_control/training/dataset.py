"""Training windows for the backbone, sampled on the fly from the libraries' training clips of one
or more skeletons.

Each sample: C context frames, a gap of G frames (shared by a batch, drawn from [min_gap, 30]),
one target keyframe, canonical w.r.t. the last context frame, and its skeleton (descriptor and
present-feature mask). Conditioning is drawn at random so one model learns every use the runtime
makes of it (COMET trains on random subsets for the same reason):
- the target's given mask: full pose, root only, root + upper body (style poses), or a random
  subset - the root with probability 0.7, each effector (hands, feet, head) with 0.4, a random
  fraction of the joints;
- joint-level goals inside the gap: with probability `goal_probability`, one or two gap frames
  get a random non-empty subset of effectors, the pelvis position and joints as goals;
- style dropout, so the model also works with no style.
A feature the skeleton lacks is never given.

Reaching augmentation: the library's arms hold a few style postures, so on their own they would
teach the model only those hand positions. With probability `reach_probability` a window's arm
(or both, sometimes with the waist) is blended after the context, with a smoothstep over a random
duration, from its recorded motion to a random arm configuration in a plausible range, and the
effectors are recomputed by forward kinematics; the hand (at the reach's end frame and/or the
target) is then usually a goal. This covers the arm's workspace so that a hand goal anywhere in
reach is a pose the model has seen (learned reaching, WANDR-style, without reaching mocap).
"""

from __future__ import annotations

import numpy as np

from g1_control.generator import features as F
from g1_control.generator import skeleton as S
from g1_control.generator.inbetween import CONTEXT_FRAMES, MAX_GAP, fill_target, interpolate
from g1_control.robot import g1

UPPER = np.zeros(F.DIM, dtype=bool)
UPPER[[9 + j for j in g1.UPPER_BODY_JOINTS]] = True
UPPER[F.FINGERS] = True
ROOT_MASK = np.zeros(F.DIM, dtype=bool)
ROOT_MASK[F.ROOT] = True
EFFECTOR_MASKS = np.zeros((F.NUM_EFFECTORS, F.DIM), dtype=bool)
for _k, _name in enumerate(F.EFFECTOR_BODIES):
    EFFECTOR_MASKS[_k, F.effector_slice(_name)] = True
PELVIS_MASK = np.zeros(F.DIM, dtype=bool)
PELVIS_MASK[F.ROOT_POS] = True
MASK_KINDS = ("full", "root", "root+upper", "subset")
MASK_PROBS = (0.35, 0.15, 0.15, 0.35)
ARM_SLOTS = {"left": list(g1.ARM_JOINTS[:7]), "right": list(g1.ARM_JOINTS[7:])}
"""Per arm: shoulder pitch, roll, yaw, elbow, wrist roll, pitch, yaw (g1.JOINT_NAMES order)."""
ARM_RANGE = ((-2.3, 0.4), (-0.2, 1.3), (-0.9, 0.9), (-0.5, 1.7), (-0.8, 0.8), (-0.6, 0.6), (-0.6, 0.6))
"""Random reach configurations per arm joint (left arm; the right arm's roll/yaw angles mirrored)."""
WAIST_RANGE = {"waist_yaw_joint": (-0.6, 0.6), "waist_roll_joint": (-0.15, 0.15), "waist_pitch_joint": (-0.05, 0.45)}


class WindowSampler:
    def __init__(self, clip_feats: list[np.ndarray], styles: list[int], num_styles: int, seed: int = 0,
                 min_gap: int = 5, style_dropout: float = 0.1, skeletons: list[str] | None = None,
                 goal_probability: float = 0.5, reach_probability: float = 0.25):
        need = CONTEXT_FRAMES + MAX_GAP + 1
        skeletons = skeletons or ["g1_29dof"] * len(clip_feats)
        keep = [i for i, c in enumerate(clip_feats) if c.shape[0] >= need]
        if not keep:
            raise ValueError(f"no training clip has the {need} frames a window needs")
        self.clips = [clip_feats[i] for i in keep]
        self.styles = [styles[i] for i in keep]
        self.skeleton_names = sorted(set(skeletons[i] for i in keep))
        self.skel = np.array([self.skeleton_names.index(skeletons[i]) for i in keep])
        self.present = np.stack([F.present_mask(S.skeleton(n).present) for n in self.skeleton_names])
        self.descriptor = np.stack([S.skeleton(n).descriptor().reshape(-1) for n in self.skeleton_names])
        lengths = np.array([c.shape[0] - need + 1 for c in self.clips], dtype=float)
        # every skeleton weighs the same, whatever its library's size
        p = lengths.copy()
        for k in range(len(self.skeleton_names)):
            sel = self.skel == k
            p[sel] /= p[sel].sum()
        self.p = p / p.sum()
        self.rng = np.random.default_rng(seed)
        self.min_gap = min_gap
        self.num_styles = num_styles
        self.style_dropout = style_dropout
        self.goal_probability = goal_probability
        self.reach_probability = reach_probability

    def _subset(self, n: int, root_p: float, eff_p: float, joint_max: float) -> np.ndarray:
        rng = self.rng
        out = np.zeros((n, F.DIM), dtype=bool)
        out[rng.random(n) < root_p] |= ROOT_MASK
        eff = rng.random((n, F.NUM_EFFECTORS)) < eff_p
        out |= (eff[:, :, None] & EFFECTOR_MASKS[None]).any(axis=1)
        frac = rng.random((n, 1)) * joint_max
        joints = rng.random((n, S.NUM_SLOTS)) < frac
        out[:, F.JOINT_SLOTS] |= joints
        return out

    def masks(self, b: int) -> np.ndarray:
        kind = self.rng.choice(len(MASK_KINDS), size=b, p=MASK_PROBS)
        out = np.zeros((b, F.DIM), dtype=bool)
        out[kind == 0] = True
        out[kind == 1] = ROOT_MASK
        out[kind == 2] = ROOT_MASK | UPPER
        chosen = kind == 3
        if chosen.any():
            out[chosen] = self._subset(int(chosen.sum()), 0.7, 0.4, 0.4)
        return out

    def gap_goals(self, b: int, gap: int, present: np.ndarray | None = None) -> np.ndarray:
        """(b, gap, D) bool: goal masks on gap frames (only features in `present` (b, D))."""
        out = np.zeros((b, gap, F.DIM), dtype=bool)
        for i in np.flatnonzero(self.rng.random(b) < self.goal_probability):
            for _ in range(int(self.rng.integers(1, 3))):
                k = int(self.rng.integers(0, gap))
                m = self._subset(1, 0.0, 0.45, 0.25)[0]
                if self.rng.random() < 0.3:
                    m |= PELVIS_MASK
                if present is not None:
                    m &= present[i]
                if not m.any():
                    m |= EFFECTOR_MASKS[int(self.rng.integers(0, F.NUM_EFFECTORS))]
                out[i, k] |= m
        return out

    def _reach(self, wins: np.ndarray, present: np.ndarray, gap: int) -> list[tuple[int, list[str], int]]:
        """Blend random windows' arms toward random configurations (in place, effectors recomputed);
        returns (window, arms, end frame index in the gap or -1 for the target) per reach."""
        rng = self.rng
        picked = np.flatnonzero(rng.random(len(wins)) < self.reach_probability)
        out: list = []
        if not picked.size:
            return out
        length = wins.shape[1]
        t = np.arange(length)
        for i in picked:
            arms = [["left"], ["right"], ["left", "right"]][rng.choice(3, p=(0.4, 0.4, 0.2))]
            slots, target = [], []
            for arm in arms:
                sign = 1.0 if arm == "left" else -1.0
                for k, (lo, hi) in zip(ARM_SLOTS[arm], ARM_RANGE):
                    v = rng.uniform(lo, hi)
                    if k in (ARM_SLOTS[arm][1], ARM_SLOTS[arm][2], ARM_SLOTS[arm][4], ARM_SLOTS[arm][6]):
                        v *= sign
                    slots.append(k)
                    target.append(v)
            if rng.random() < 0.5:
                for name, (lo, hi) in WAIST_RANGE.items():
                    slots.append(g1.JOINT_INDEX[name])
                    target.append(rng.uniform(lo, hi))
            slots_a = np.array(slots)
            keep = present[i, F.JOINT_SLOTS[slots_a]]
            slots_a, target_a = slots_a[keep], np.clip(np.array(target)[keep], g1.Q_MIN_RAD[slots_a[keep]],
                                                        g1.Q_MAX_RAD[slots_a[keep]])
            start = CONTEXT_FRAMES - 1 + int(rng.integers(0, max(1, gap // 3)))
            end = int(rng.integers(min(start + 6, length - 1), length))
            a = np.clip((t - start) / max(1, end - start), 0.0, 1.0)
            a = a * a * (3 - 2 * a)
            cols = F.JOINT_SLOTS[slots_a]
            wins[i][:, cols] = (1 - a[:, None]) * wins[i][:, cols] + a[:, None] * target_a[None]
            out.append((int(i), arms, end - CONTEXT_FRAMES if end < length - 1 else -1))
        idx = [r[0] for r in out]
        wins[idx] = F.fix_effectors(wins[idx]) * present[idx][:, None, :].astype(float)
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
        skel = self.skel[which]
        present = self.present[skel]
        reaches = self._reach(wins, present, gap) if self.reach_probability > 0 else []
        mask = self.masks(batch)
        goals = self.gap_goals(batch, gap, present)
        for i, arms, end in reaches:
            # mostly: the root and the reaching hand(s) given - at the reach's end frame when it
            # falls inside the gap, and on the target
            if self.rng.random() < 0.7:
                hands = np.zeros(F.DIM, dtype=bool)
                for arm in arms:
                    hands[F.effector_slice(f"{arm}_wrist_yaw_link")] = True
                mask[i] = ROOT_MASK | hands | (mask[i] & (self.rng.random(F.DIM) < 0.3))
                if end >= 0:
                    goals[i, end] |= hands
        mask &= present
        goals &= present[:, None, :]
        context, target, truth = wins[:, :CONTEXT_FRAMES], wins[:, -1], wins[:, CONTEXT_FRAMES:-1]
        base = interpolate(context[:, -1], fill_target(context[:, -1], target, mask, gap), gap)
        return {"context": context, "target": np.where(mask, target, 0.0), "given": mask.astype(float),
                "base": base, "gap_goal": np.where(goals, truth, 0.0), "gap_given": goals.astype(float),
                "style": style, "skeleton": self.descriptor[skel], "present": present.astype(float),
                "truth": truth, "gap": np.array(gap)}
