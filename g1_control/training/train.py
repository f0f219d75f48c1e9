"""Training of the in-betweening backbone: `g1 train generator` (single process or torchrun/DDP).

Loss per gap frame (raw canonical units): L1 on pelvis position and 6D rotation, joint angles,
effector positions, and on the global position and rotation of all 30 bodies through
differentiable forward kinematics (what L2P and L2Q measure), plus the duration head's L1 on
log frames. Checkpoint, config, loss history and a loss plot go to the output folder; the
shipped model is exported to ONNX for the runtime.
"""

from __future__ import annotations

import json
import os
import sys
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

from g1_control.errors import G1ControlError
from g1_control.generator import features as F
from g1_control.generator.features import load_split


@dataclass
class TrainConfig:
    steps: int = 6000
    batch: int = 128
    lr: float = 1e-3
    weight_decay: float = 1e-4
    warmup_steps: int = 200
    seed: int = 0
    threads: int = 1
    """Torch threads per process. Measured on the shared 2-core machine: one thread is 3-10x faster
    per step than two (the second thread spins against other developers' jobs)."""
    eval_every: int = 500
    time_limit_s: float = 25 * 60
    """Stops early (keeping the best model) past this wall time: the 30-minute CPU budget."""
    fk_weight: float = 1.0
    normalized_position_weight: float = 0.5
    """Weight of the FK position error divided by each body coordinate's spread over training
    windows - what L2P measures. Measured: without it the model left L2P above motion matching
    (vertical errors, small in metres, dominate the normalized metric)."""
    model: dict = field(default_factory=dict)
    """Overrides of BackboneConfig fields (d_model, layers, ...)."""


def _fk_terms(pred, truth, pos_scale=None):
    import torch

    from g1_control.generator.fk import fk_torch

    def bodies(x):
        a, b = x[..., 3:6], x[..., 6:9]
        xa = a / a.norm(dim=-1, keepdim=True).clamp_min(1e-6)
        b = b - (xa * b).sum(-1, keepdim=True) * xa
        yb = b / b.norm(dim=-1, keepdim=True).clamp_min(1e-6)
        rot = torch.stack([xa, yb, torch.cross(xa, yb, dim=-1)], dim=-1)
        return fk_torch(x[..., :3], rot, x[..., 9:38])

    pp, pr = bodies(pred)
    tp, tr = bodies(truth)
    norm = ((pp - tp).abs() / pos_scale).mean() if pos_scale is not None else torch.zeros(())
    return (pp - tp).abs().mean(), (pr - tr).abs().mean(), norm


def loss_fn(model, batch, fk_weight: float, subsample: bool = True, pos_scale=None, norm_weight: float = 0.0):
    import torch

    pred, duration = model(batch["context"], batch["target"], batch["given"], batch["base"], batch["style"])
    truth = batch["truth"]
    err = (pred - truth).abs()
    terms = {
        "root": err[..., F.ROOT_POS].mean() * 2.0 + err[..., F.ROOT_ROT].mean(),
        "joints": err[..., F.JOINTS].mean(),
        "effectors": err[..., F.EFFECTORS].mean(),
    }
    # FK through 29 joints is the costliest part of a step: a random quarter of the frames suffices.
    b, g = truth.shape[:2]
    pick = torch.randperm(b * g)[: max(1, b * g // 4)] if subsample else torch.arange(b * g)
    pos, rot, norm = _fk_terms(pred.reshape(b * g, -1)[pick], truth.reshape(b * g, -1)[pick], pos_scale)
    terms["fk_pos"] = pos * 2.0 * fk_weight
    terms["fk_rot"] = rot * fk_weight
    if pos_scale is not None:
        terms["fk_pos_norm"] = norm * norm_weight
    gap = float(truth.shape[1])
    terms["duration"] = 0.1 * (torch.log(duration + 1.0) - np.log(gap + 1.0)).abs().mean()
    return sum(terms.values()), terms


def _to_torch(batch: dict):
    import torch

    out = {}
    for k, v in batch.items():
        if k == "style":
            out[k] = torch.as_tensor(v, dtype=torch.long)
        elif k != "gap":
            out[k] = torch.as_tensor(v, dtype=torch.float32)
    return out


def check_splits(library_root: str | Path | None) -> None:
    """Refuse a library whose train or held-out ('test') split has no clip long enough for a window."""
    from g1_control.motion.library import LibraryError, MotionLibrary, default_library_dir
    from g1_control.training.dataset import CONTEXT_FRAMES, MAX_GAP

    lib = MotionLibrary(library_root or default_library_dir())
    need = CONTEXT_FRAMES + MAX_GAP + 1
    for split, what in (("train", "training"), ("test", "held-out")):
        entries = lib.select(split)
        if not entries:
            raise LibraryError(f"{lib.root}: the '{split}' split has no clips, so there is no {what} data; rebuild "
                               "the library with clips in both splits (g1 library build)")
        if max(e.num_frames for e in entries) < need:
            raise LibraryError(f"{lib.root}: no clip of the '{split}' ({what}) split has the {need} frames a "
                               "training window needs")


def train(out_dir: str | Path, config: TrainConfig, library_root: str | Path | None = None,
          progress: bool = True) -> dict:
    import torch
    import torch.distributed as dist

    from g1_control.generator.styles import STYLES
    from g1_control.training.backbone import Backbone, BackboneConfig
    from g1_control.training.dataset import WindowSampler

    world = int(os.environ.get("WORLD_SIZE", "1"))
    rank = int(os.environ.get("RANK", "0"))
    if world > 1:
        dist.init_process_group("gloo")
    torch.manual_seed(config.seed)
    torch.set_num_threads(max(1, config.threads))
    check_splits(library_root)
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    feats, styles = load_split(library_root, "train")
    sampler = WindowSampler(feats, styles, len(STYLES), seed=config.seed + 1000 * rank)
    model_cfg = BackboneConfig(num_styles=len(STYLES), **config.model)
    model = Backbone(model_cfg)
    stats = np.concatenate([sampler.sample(256)["truth"].reshape(-1, F.DIM) for _ in range(8)])
    model.feat_mean.copy_(torch.as_tensor(stats.mean(0), dtype=torch.float32))
    model.feat_std.copy_(torch.as_tensor(stats.std(0) + 1e-3, dtype=torch.float32))
    from g1_control.generator.fk import fk_numpy

    body_pos, _ = fk_numpy(stats[:, :3], F.rot6d_to_matrix(stats[:, 3:9]), stats[:, 9:38])
    pos_scale = torch.as_tensor(body_pos.std(axis=0) + 1e-3, dtype=torch.float32)
    net = torch.nn.parallel.DistributedDataParallel(model) if world > 1 else model
    opt = torch.optim.AdamW(model.parameters(), lr=config.lr, weight_decay=config.weight_decay)
    sched = torch.optim.lr_scheduler.LambdaLR(opt, lambda s: min(1.0, (s + 1) / config.warmup_steps) * 0.5 * (
        1 + np.cos(np.pi * min(1.0, s / config.steps))))
    # a fixed validation set from the held-out clips (gaps of 15 and 30 frames)
    vfeats, vstyles = load_split(library_root, "test")
    vsampler = WindowSampler(vfeats, vstyles, len(STYLES), seed=12345, style_dropout=0.0)
    history: list[dict] = []
    best: tuple[float, dict[str, torch.Tensor] | None] = (float("inf"), None)

    val_batches = [_to_torch(vsampler.sample(128, gap=g)) for g in (15, 30)]

    def held_out_loss() -> float:
        model.eval()
        with torch.no_grad():
            return float(np.mean([loss_fn(model, b, config.fk_weight, False, pos_scale,
                                                   config.normalized_position_weight)[0].item() for b in val_batches]))

    # the untrained model is exactly interpolation (zero-initialized output heads): the reference
    initial_val = held_out_loss()
    started = time.perf_counter()
    bar = None
    if progress and rank == 0:
        from tqdm import tqdm

        bar = tqdm(total=config.steps, desc="train generator", unit="step", file=sys.stderr)
    step = 0
    for step in range(config.steps):
        batch = _to_torch(sampler.sample(config.batch // world))
        model.train()
        loss, terms = loss_fn(net, batch, config.fk_weight, True, pos_scale, config.normalized_position_weight)
        opt.zero_grad(set_to_none=True)
        loss.backward()
        torch.nn.utils.clip_grad_norm_(model.parameters(), 1.0)
        opt.step()
        sched.step()
        if bar is not None:
            bar.update()
            bar.set_postfix_str(f"loss {loss.item():.4f}")
        record = {"step": step, "loss": loss.item(), **{k: v.item() for k, v in terms.items()}}
        last = step == config.steps - 1 or time.perf_counter() - started > config.time_limit_s
        if (step + 1) % config.eval_every == 0 or last:
            vl = held_out_loss()
            record["val_loss"] = vl
            if rank == 0 and vl < best[0]:
                best = (vl, {k: v.detach().clone() for k, v in model.state_dict().items()})
        history.append(record)
        if last:
            break
    if bar is not None:
        bar.close()
    wall = time.perf_counter() - started
    result = {"steps": step + 1, "wall_s": wall, "initial_val_loss": initial_val, "best_val_loss": best[0],
              "world_size": world}
    if rank == 0:
        if best[1] is None:  # every validation loss was NaN
            raise G1ControlError(f"training gave no finite validation loss in {step + 1} steps; nothing saved")
        model.load_state_dict(best[1])
        save_checkpoint(model, out / "backbone.pt", config)
        (out / "train_config.json").write_text(json.dumps({"train": asdict(config), "model": model_cfg.to_dict(),
                                                           "result": result}, indent=2))
        (out / "loss_history.json").write_text(json.dumps(history))
        plot_losses(history, out / "loss.png")
        export_onnx(model, out / "backbone.onnx")
        from g1_control.generator.style_stats import write_style_stats
        from g1_control.motion.library import default_library_dir

        write_style_stats(library_root or default_library_dir(), out / "style_stats.json")
    if world > 1:
        dist.destroy_process_group()
    return result


def save_checkpoint(model, path: Path, config: TrainConfig | None = None) -> None:
    import torch

    torch.save({"model_config": model.config.to_dict(), "state_dict": model.state_dict(),
                "train_config": asdict(config) if config else None}, path)


def load_checkpoint(path: str | Path):
    import torch

    from g1_control.training.backbone import Backbone, BackboneConfig

    blob = torch.load(path, map_location="cpu", weights_only=True)
    config = dict(blob["model_config"])
    config.setdefault("pose_refines_root", False)  # checkpoints from before the option
    model = Backbone(BackboneConfig(**config))
    model.load_state_dict(blob["state_dict"])
    model.eval()
    return model


def plot_losses(history: list[dict], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    steps = np.array([h["step"] for h in history])
    fig, ax = plt.subplots(figsize=(7, 4))
    loss = np.array([h["loss"] for h in history])
    k = max(1, len(loss) // 100)
    smooth = np.convolve(loss, np.ones(k) / k, mode="valid")
    ax.plot(steps[:len(smooth)] + k // 2, smooth, label="train loss (smoothed)")
    val = [(h["step"], h["val_loss"]) for h in history if "val_loss" in h]
    if val:
        ax.plot(*zip(*val), "o-", label="held-out loss")
    ax.set_yscale("log")
    ax.set_xlabel("step")
    ax.set_ylabel("loss")
    ax.set_title("in-betweening backbone")
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def export_onnx(model, path: Path) -> None:
    import torch

    model.eval()
    b, g = 2, 15
    args = (torch.zeros(b, 10, F.DIM), torch.zeros(b, F.DIM), torch.ones(b, F.DIM), torch.zeros(b, g, F.DIM),
            torch.zeros(b, dtype=torch.long))
    torch.onnx.export(model, args, str(path), input_names=["context", "target", "given", "base", "style"],
                      output_names=["frames", "duration"], dynamo=False, opset_version=17,
                      dynamic_axes={"context": {0: "batch"}, "target": {0: "batch"}, "given": {0: "batch"},
                                    "base": {0: "batch", 1: "gap"}, "style": {0: "batch"},
                                    "frames": {0: "batch", 1: "gap"}, "duration": {0: "batch"}})
