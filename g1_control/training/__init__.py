"""Training of the generator's networks (torch; `g1 train ...`). The runtime in g1_control/generator/
never imports this package: it runs exported ONNX files."""

from pathlib import Path

TRAINING_RECORDS_DIR = Path(__file__).resolve().parents[2] / "training_records"
"""Where a training run of a shipped model leaves what the runtime never reads (the torch checkpoint,
the loss history and its plot): the repository's training_records/, outside the import package."""
