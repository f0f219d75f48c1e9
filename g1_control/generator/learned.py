"""The trained backbone as an Inbetweener: ONNX Runtime at run time (no torch needed), or the
torch checkpoint for tests and evaluation right after training.

A model folder holds backbone.onnx, model.json (format, the skeletons it was trained on),
style_stats.json and feedback.npz (the per-style reference mixtures, feedback.py). A model serves
one skeleton at a time (`skeleton=`); asking it for a skeleton it was not trained on raises
SkeletonError naming both.
"""

from __future__ import annotations

import functools
import json
from pathlib import Path

import numpy as np

from g1_control.generator import features as F
from g1_control.generator import skeleton as S
from g1_control.generator.inbetween import MAX_GAP, Inbetweener, fill_target, interpolate

SHIPPED_DIR = Path(__file__).resolve().parents[1] / "policies" / "generator"
"""policies/generator/: the shipped model (trained on every skeleton)."""
MODEL_FORMAT = 2
PATCH = 2
"""Frames per token of the backbone (training/backbone.py)."""
PADDED_GAP = -(-MAX_GAP // PATCH) * PATCH
"""The exported graph's fixed gap length (frames); shorter gaps are masked inside it."""


def model_info(path: str | Path) -> dict:
    """model.json next to a backbone ONNX file ({} when missing)."""
    meta = Path(path).parent / "model.json"
    return json.loads(meta.read_text()) if meta.is_file() else {}


def check_skeleton(path: str | Path, skeleton: str) -> None:
    """Raise SkeletonError unless the model at `path` was trained for `skeleton`."""
    info = model_info(path)
    trained = info.get("skeletons", ["g1_29dof"])
    if skeleton not in trained:
        raise S.SkeletonError(f"{path}: this generator model was trained for {', '.join(trained)}; the robot is "
                              f"{skeleton}. Use a model trained on {skeleton} (g1 train generator --skeletons "
                              f"{skeleton}) or the shipped model")


def prepare_inputs(context, target, target_mask, gap, skeleton: str | np.ndarray = "g1_29dof",
                   gap_goal=None, gap_mask=None, style=None) -> dict[str, np.ndarray]:
    """The model's inputs from canonical arrays: float32, the gap padded to the graph's fixed
    PADDED_GAP frames (gap_len says how many are real). skeleton: a name, or a tuple
    (descriptors (B, W), present masks (B, D))."""
    b = context.shape[0]
    last = context[:, -1]
    filled = fill_target(last, target, target_mask, gap)
    padded = PADDED_GAP
    base = np.empty((b, padded, F.DIM), np.float32)
    base[:, :gap] = interpolate(last, filled, gap)
    base[:, gap:] = filled[:, None, :]
    goal = np.zeros((b, padded, F.DIM), np.float32)
    given = np.zeros((b, padded, F.DIM), np.float32)
    if gap_goal is not None:
        goal[:, :gap] = np.where(gap_mask, gap_goal, 0.0)
        given[:, :gap] = gap_mask
    if isinstance(skeleton, str):
        desc, present = _skeleton_inputs(skeleton, b)
    else:
        desc, present = skeleton
    return {"context": context.astype(np.float32), "target": np.where(target_mask, target, 0.0).astype(np.float32),
            "target_given": target_mask.astype(np.float32), "base": base,
            "gap_goal": goal, "gap_given": given,
            "style": np.zeros(b, np.int64) if style is None else np.asarray(style, dtype=np.int64),
            "skeleton": np.ascontiguousarray(desc, dtype=np.float32),
            "present": np.ascontiguousarray(present, dtype=np.float32),
            "gap_len": np.full(b, gap, np.int64)}


@functools.lru_cache(maxsize=32)
def _skeleton_inputs(name: str, b: int) -> tuple[np.ndarray, np.ndarray]:
    """A skeleton's descriptor and present-feature rows for a batch of b (cached: every replan
    asks for the same ones)."""
    sk = S.skeleton(name)
    desc = np.ascontiguousarray(np.broadcast_to(sk.descriptor().reshape(1, -1), (b, S.NUM_SLOTS * S.DESCRIPTOR_WIDTH)),
                                dtype=np.float32)
    present = np.ascontiguousarray(np.broadcast_to(F.present_mask(sk.present)[None], (b, F.DIM)), dtype=np.float32)
    for a in (desc, present):
        a.setflags(write=False)
    return desc, present


INPUT_NAMES = ("context", "target", "target_given", "base", "gap_goal", "gap_given", "style", "skeleton", "present",
               "gap_len")


def finish(frames: np.ndarray, gap: int) -> np.ndarray:
    frames = frames[:, :gap].astype(float)
    F.orthonormalize_rot6d(frames)
    return frames


class _Goals:
    """Joint-level goals on gap frames for the next infill call (set_goals), consumed by it."""

    skeleton: str = "g1_29dof"

    def set_goals(self, goal: np.ndarray | None, mask: np.ndarray | None) -> None:
        """(B, gap, D) goal values and masks, canonical, for the next infill (None clears)."""
        self._goal, self._goal_mask = goal, mask

    def _take_goals(self):
        out = getattr(self, "_goal", None), getattr(self, "_goal_mask", None)
        self._goal = self._goal_mask = None
        return out


class OnnxInbetweener(_Goals, Inbetweener):
    name = "backbone"

    def __init__(self, path: str | Path | None = None, threads: int = 1, skeleton: str = "g1_29dof"):
        import onnxruntime as ort

        path = Path(path) if path else SHIPPED_DIR / "backbone.onnx"
        if not path.is_file():
            raise FileNotFoundError(f"{path}: no backbone ONNX file; train one with `g1 train generator`")
        info = model_info(path)
        if info.get("format", 1) != MODEL_FORMAT:
            raise S.SkeletonError(f"{path}: model format {info.get('format', 1)}, this runtime reads format "
                                  f"{MODEL_FORMAT}; retrain with `g1 train generator`")
        check_skeleton(path, skeleton)
        self.path = path
        self.skeleton = skeleton
        opts = ort.SessionOptions()
        opts.intra_op_num_threads = threads
        opts.inter_op_num_threads = 1
        opts.graph_optimization_level = ort.GraphOptimizationLevel.ORT_ENABLE_ALL
        self.session = ort.InferenceSession(str(path), opts, providers=["CPUExecutionProvider"])
        self.last_duration: np.ndarray | None = None

    def infill(self, context, target, target_mask, gap, style):
        self.check(context, target, target_mask, gap, style)
        goal, mask = self._take_goals()
        feed = prepare_inputs(context, target, target_mask, gap, self.skeleton, goal, mask, style)
        frames, duration = self.session.run(None, feed)
        self.last_duration = duration
        return finish(frames, gap)


class TorchInbetweener(_Goals, Inbetweener):
    name = "backbone"

    def __init__(self, model, skeleton: str = "g1_29dof"):
        self.model = model
        self.skeleton = skeleton

    def infill(self, context, target, target_mask, gap, style):
        import torch

        self.check(context, target, target_mask, gap, style)
        goal, mask = self._take_goals()
        feed = prepare_inputs(context, target, target_mask, gap, self.skeleton, goal, mask, style)
        with torch.no_grad():
            frames, _ = self.model(*[torch.as_tensor(feed[k]) for k in INPUT_NAMES])
        return finish(frames.numpy(), gap)
