"""The import package carries what the runtime reads, not what training leaves behind: no torch
checkpoint, loss history or loss plot under g1_control/ (they live in training_records/, outside it),
while every file the generators load at run time is there."""

from __future__ import annotations

from g1_control.generator.learned import SHIPPED_DIR
from g1_control.generator.lmm import SHIPPED_LMM_DIR
from g1_control.training import TRAINING_RECORDS_DIR
from tests.paths import REPO

LEFTOVERS = (".pt", "loss_history.json", "loss.png")


def test_no_training_leftovers_inside_the_import_package():
    leftovers = [str(p.relative_to(REPO)) for p in (REPO / "g1_control").rglob("*") if p.name.endswith(LEFTOVERS)]
    assert not leftovers, f"training leftovers in the import package: {leftovers}"


def test_the_runtime_files_stay_and_the_records_of_the_shipped_models_are_kept_beside_the_package():
    for name in ("backbone.onnx", "model.json", "feedback.npz", "style_stats.json", "train_config.json"):
        assert (SHIPPED_DIR / name).is_file(), name
    for name in ("lmm.onnx", "model.json", "train_config.json"):
        assert (SHIPPED_LMM_DIR / name).is_file(), name
    assert TRAINING_RECORDS_DIR == REPO / "training_records"
    for folder, checkpoint in ((TRAINING_RECORDS_DIR / "generator", "backbone.pt"),
                               (TRAINING_RECORDS_DIR / "generator" / "lmm", "lmm.pt")):
        for name in (checkpoint, "loss_history.json", "loss.png"):
            assert (folder / name).is_file(), folder / name
