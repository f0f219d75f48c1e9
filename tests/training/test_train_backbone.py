"""The backbone: training end to end (tiny model, tiny library), ONNX export with a dynamic
gap, DDP under torchrun, and the shipped checkpoint."""

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from g1_control.generator import evaluation as E
from g1_control.generator.baselines import InterpolationInbetweener
from g1_control.generator.learned import SHIPPED_DIR, OnnxInbetweener, TorchInbetweener
from g1_control.library.builder import LibraryConfig, build_library
from g1_control.training.train import TrainConfig, load_checkpoint, load_split, train

TINY = {"d_model": 16, "layers": 1, "heads": 2, "ff": 32, "root_d_model": 8, "root_layers": 1}
ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def library(tmp_path_factory):
    out = tmp_path_factory.mktemp("lib")
    build_library(out, LibraryConfig(rollout_seconds=10.0, rollouts_per_style=1, rollout_styles=("default",),
                                     dance=False, demo=False, clip_seconds=2.0), progress=False)
    return out


@pytest.fixture(scope="module")
def trained(library, tmp_path_factory):
    out = tmp_path_factory.mktemp("run")
    result = train(out, TrainConfig(steps=60, batch=32, eval_every=20, warmup_steps=5, lr=3e-3, model=TINY),
                   library, progress=False)
    return out, result


def test_training_writes_checkpoint_onnx_config_plot_and_learns(trained):
    out, result = trained
    for name in ("backbone.pt", "backbone.onnx", "train_config.json", "loss_history.json", "loss.png", "style_stats.json"):
        assert (out / name).is_file(), name
    history = json.loads((out / "loss_history.json").read_text())
    assert len(history) == 60 and sum("val_loss" in h for h in history) == 3
    # held-out loss below the untrained model's, which is plain interpolation
    assert result["best_val_loss"] < 0.95 * result["initial_val_loss"]
    config = json.loads((out / "train_config.json").read_text())
    assert config["model"]["d_model"] == 16 and config["result"]["steps"] == 60


@pytest.mark.parametrize("gap", [7, 30])
def test_onnx_export_matches_torch_for_any_gap(trained, library, gap):
    out, _ = trained
    feats, styles = load_split(library, "test")
    w = E.make_windows(feats, styles, gap, stride=10)
    rng = np.random.default_rng(0)
    mask = rng.random((len(w.frames), 50)) < 0.5
    mask[:, :9] = True
    args = (w.context, w.target, mask, gap, w.style)
    a = OnnxInbetweener(out / "backbone.onnx").infill(*args)
    b = TorchInbetweener(load_checkpoint(out / "backbone.pt")).infill(*args)
    assert a.shape == (len(w.frames), gap, 50)
    assert np.abs(a - b).max() < 1e-4


def test_trained_backbone_beats_interpolation_on_held_out_windows(trained, library):
    out, _ = trained
    feats, styles = load_split(library, "test")
    tr_feats, tr_styles = load_split(library, "train")
    w = E.make_windows(feats, styles, 15, stride=5)
    stats = E.PositionStats.from_windows(E.make_windows(tr_feats, tr_styles, 15))
    ours = E.score(OnnxInbetweener(out / "backbone.onnx"), w, stats)
    interp = E.score(InterpolationInbetweener(), w, stats)
    assert ours.l2q < interp.l2q and ours.l2p < interp.l2p


def test_torchrun_ddp_trains_with_two_processes(library, tmp_path):
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    cmd = [sys.executable, "-m", "torch.distributed.run", "--nproc-per-node", "2", "--master-port", "29517",
           "-m", "g1_control.cli.main", "train", "generator", "-o", str(tmp_path), "--library", str(library),
           "--steps", "6", "--batch", "8", "--eval-every", "3", "--model", json.dumps(TINY)]
    proc = subprocess.run(cmd, cwd=ROOT, env=env, capture_output=True, text=True, timeout=240, check=False)
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert "world size 2" in proc.stdout
    assert (tmp_path / "backbone.onnx").is_file()


def test_shipped_model_is_small_and_loads():
    onnx_path, ckpt = SHIPPED_DIR / "backbone.onnx", SHIPPED_DIR / "backbone.pt"
    assert ckpt.stat().st_size <= 20 * 2**20 and onnx_path.stat().st_size <= 20 * 2**20
    config = json.loads((SHIPPED_DIR / "train_config.json").read_text())
    assert config["result"]["wall_s"] <= 30 * 60
    model = OnnxInbetweener(onnx_path)
    ctx = np.zeros((1, 10, 50))
    ctx[..., 2], ctx[..., 3], ctx[..., 7] = 0.75, 1.0, 1.0
    out = model.infill(ctx, ctx[:, -1], np.ones((1, 50), bool), 20, np.zeros(1, int))
    assert out.shape == (1, 20, 50) and np.all(np.isfinite(out))


def test_cli_help_explains_and_bad_model_json_is_named(capsys):
    from g1_control.cli.main import main

    with pytest.raises(SystemExit):
        main(["train", "generator", "--help"])
    assert "torchrun" in capsys.readouterr().out
    assert main(["train", "generator", "--model", "{bad", "--library", "/nonexistent"]) == 1
    assert "--model must be a JSON object" in capsys.readouterr().err


def test_duration_head_cannot_read_the_gap_from_the_token_layout(trained):
    import torch

    out, _ = trained
    model = load_checkpoint(out / "backbone.pt")
    rng = np.random.default_rng(1)
    ctx = torch.tensor(rng.normal(size=(3, 10, 50)), dtype=torch.float32)
    tgt = torch.tensor(rng.normal(size=(3, 50)), dtype=torch.float32)
    given, style = torch.ones(3, 50), torch.zeros(3, dtype=torch.long)
    with torch.no_grad():
        _, d10 = model(ctx, tgt, given, torch.zeros(3, 10, 50), style)
        _, d25 = model(ctx, tgt, given, torch.zeros(3, 25, 50), style)
    assert torch.allclose(d10, d25)  # the same context and target: the same predicted duration
