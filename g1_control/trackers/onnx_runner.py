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
        output = self.session.get_outputs()[0]
        self.output_name = output.name
        self.extra_inputs = extra_inputs or {}
        # A fixed-shape float output is written into one preallocated buffer through an IO binding
        # (inputs are bound to the callers' arrays, read in place at each run): this skips
        # session.run's per-call feed/fetch handling. Other outputs take the plain session.run.
        self._binding = None
        self._bound_obs: np.ndarray | None = None
        if output.type == "tensor(float)" and all(isinstance(d, int) and d > 0 for d in output.shape):
            self._out = np.zeros(output.shape, dtype=np.float32)
            binding = self.session.io_binding()
            binding.bind_output(self.output_name, "cpu", 0, np.float32, self._out.shape, self._out.ctypes.data)
            for name, value in self.extra_inputs.items():
                binding.bind_cpu_input(name, value)
            self._binding = binding

    def __call__(self, obs: np.ndarray) -> np.ndarray:
        """The first output's first row (a new array)."""
        binding = self._binding
        if binding is None:
            feeds = {self.input_name: obs, **self.extra_inputs}
            return self.session.run([self.output_name], feeds)[0][0]
        if obs is not self._bound_obs:
            binding.bind_cpu_input(self.input_name, obs)
            self._bound_obs = obs
        self.session.run_with_iobinding(binding)
        return self._out[0].copy()
