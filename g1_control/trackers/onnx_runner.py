"""A single-threaded onnxruntime session for one observation in, first output out."""

from __future__ import annotations

from pathlib import Path

import numpy as np


class OnnxRunner:
    def __init__(self, path: Path, input_name: str, extra_inputs: dict[str, np.ndarray] | None = None):
        import onnxruntime as ort

        options = ort.SessionOptions()
        # One thread: the loop is single-threaded and the networks are small MLPs (20-60 us).
        options.intra_op_num_threads = 1
        options.inter_op_num_threads = 1
        self.session = ort.InferenceSession(str(path), options, providers=["CPUExecutionProvider"])
        self.input_name = input_name
        self.output_name = self.session.get_outputs()[0].name
        self.extra_inputs = extra_inputs or {}

    def __call__(self, obs: np.ndarray) -> np.ndarray:
        feeds = {self.input_name: obs, **self.extra_inputs}
        return self.session.run([self.output_name], feeds)[0][0]
