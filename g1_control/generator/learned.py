"""The trained backbone as an Inbetweener: ONNX Runtime at run time (no torch needed), or the
torch checkpoint for tests and evaluation right after training."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from g1_control.generator import features as F
from g1_control.generator.inbetween import Inbetweener, fill_target, interpolate

SHIPPED_DIR = Path(__file__).resolve().parents[1] / "policies" / "generator"
"""policies/generator/ (g1_control/policies links to the top-level policies/ folder)."""


def _prepare(context, target, target_mask, gap):
    last = context[:, -1]
    base = interpolate(last, fill_target(last, target, target_mask, gap), gap)
    return (context.astype(np.float32), np.where(target_mask, target, 0.0).astype(np.float32),
            target_mask.astype(np.float32), base.astype(np.float32))


def _finish(frames: np.ndarray) -> np.ndarray:
    frames = frames.astype(float)
    rot = F.rot6d_to_matrix(frames[..., F.ROOT_ROT])
    frames[..., 3:6], frames[..., 6:9] = rot[..., :, 0], rot[..., :, 1]
    return frames


class OnnxInbetweener(Inbetweener):
    name = "backbone"

    def __init__(self, path: str | Path | None = None, threads: int = 1):
        import onnxruntime as ort

        path = Path(path) if path else SHIPPED_DIR / "backbone.onnx"
        if not path.is_file():
            raise FileNotFoundError(f"{path}: no backbone ONNX file; train one with `g1 train generator`")
        opts = ort.SessionOptions()
        opts.intra_op_num_threads = threads
        opts.inter_op_num_threads = 1
        self.session = ort.InferenceSession(str(path), opts, providers=["CPUExecutionProvider"])
        self.last_duration: np.ndarray | None = None

    def infill(self, context, target, target_mask, gap, style):
        self.check(context, target, target_mask, gap, style)
        ctx, tgt, given, base = _prepare(context, target, target_mask, gap)
        frames, duration = self.session.run(None, {"context": ctx, "target": tgt, "given": given, "base": base,
                                                   "style": np.asarray(style, dtype=np.int64)})
        self.last_duration = duration
        return _finish(frames)


class TorchInbetweener(Inbetweener):
    name = "backbone"

    def __init__(self, model):
        self.model = model

    def infill(self, context, target, target_mask, gap, style):
        import torch

        self.check(context, target, target_mask, gap, style)
        args = [torch.as_tensor(a) for a in _prepare(context, target, target_mask, gap)]
        with torch.no_grad():
            frames, _ = self.model(*args, torch.as_tensor(np.asarray(style), dtype=torch.long))
        return _finish(frames.numpy())
