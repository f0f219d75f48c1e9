"""Training of the in-betweening backbone: `g1 train generator` (single process or torchrun/DDP).

Loss per gap frame (raw canonical units): L1 on pelvis position and 6D rotation, joint angles,
effector positions, and on the global position and rotation of all 30 bodies through
differentiable forward kinematics (what L2P and L2Q measure), plus the duration head's L1 on
log frames, and a foot-skating term: the horizontal speed of the predicted feet (through the
same forward kinematics) on the frames where the true foot stands. Checkpoint, config, loss history and a loss plot go to the output folder; the
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
from g1_control.generator.data import load_split


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
    """Stops (keeping the best model, the learning-rate schedule finished) past this much CPU time
    of the training process: the 30-minute compute budget on one core. CPU time, not wall time:
    this machine is shared, and other jobs' load stretches the wall clock several times over."""
    wall_limit_s: float = 50 * 60
    """A hard stop on the wall clock whatever the load (the schedule is finished by then too)."""
    fk_weight: float = 1.0
    normalized_position_weight: float = 0.5
    """Weight of the FK position error divided by each body coordinate's spread over training
    windows - what L2P measures. Measured: without it the model left L2P above motion matching
    (vertical errors, small in metres, dominate the normalized metric)."""
    goal_weight: float = 1.0
    """Weight of the error at joint-level goals on gap frames (given joints and root, and effector
    positions through FK of the predicted joints - what the model-only goal benchmark measures).
    Measured at 4.0: the goal term was over half the loss at the end and the reconstruction terms
    had barely moved (held-out L2P 1.53 at 15 frames)."""
    skate_weight: float = 0.1
    """Weight of the foot-skating term (stance_foot_speed, m/s): the predicted feet's horizontal
    speed where the true foot stands. 0 turns it off (and skips its forward kinematics).
    Measured (seed 0, 6000 steps, the gated library of BUILD_VERSION 3, `g1 bench generator`):
    the backbone's skating at gap 30 0.203 -> 0.125 m/s (motion matching 0.104, ground truth
    0.046), L2P@30 1.367 -> 1.387, L2Q@30 0.447 -> 0.455, NPSS@30 0.0138 -> 0.0143. Still above
    motion matching, so that model was not shipped; a larger weight is untried."""
    skeletons: tuple[str, ...] = ("g1_29dof",)
    """Skeletons to train on, each from its own library (skeleton.SKELETONS)."""
    goal_probability: float = 0.5
    reach_probability: float = 0.25
    """Share of training windows given a random arm reach (dataset.py: the reaching augmentation)."""
    model: dict = field(default_factory=dict)
    """Overrides of BackboneConfig fields (d_model, layers, ...)."""


def _rot6d_torch(x):
    import torch

    a, b = x[..., 0:3], x[..., 3:6]
    xa = a / a.norm(dim=-1, keepdim=True).clamp_min(1e-6)
    b = b - (xa * b).sum(-1, keepdim=True) * xa
    yb = b / b.norm(dim=-1, keepdim=True).clamp_min(1e-6)
    return torch.stack([xa, yb, torch.cross(xa, yb, dim=-1)], dim=-1)


def _bodies(x):
    from g1_control.generator.fk import fk_torch

    return fk_torch(x[..., :3], _rot6d_torch(x[..., 3:9]), x[..., 9:38])


def _fk_terms(pred, truth, pos_scale=None):
    import torch

    pp, pr = _bodies(pred)
    tp, tr = _bodies(truth)
    norm = ((pp - tp).abs() / pos_scale).mean() if pos_scale is not None else torch.zeros(())
    return (pp - tp).abs().mean(), (pr - tr).abs().mean(), norm


STANCE_MAX_SPEED_MPS = 0.3
"""A true foot stands (for the skating term) when it is at stance height (evaluation.py's band, as
`g1 bench generator` judges skating) at both ends of a frame step and moves slower than this
horizontally: the speed limit of the library's contact labels (motion/contacts.py)."""


def stance_foot_speed(pred_feet, truth_feet, fps: float = 30.0):
    """Foot skating as a loss: pred_feet, truth_feet (B, T, 2, 3) ankle positions (m) -> the mean
    horizontal speed (m/s) of the predicted feet over the frame steps where the true foot stands
    (STANCE_MAX_SPEED_MPS), 0 when no foot stands. Differentiable in pred_feet."""
    import torch

    from g1_control.generator.evaluation import CONTACT_BAND_M, STANCE_ANKLE_Z_M

    with torch.no_grad():
        low = truth_feet[..., 2] < STANCE_ANKLE_Z_M + CONTACT_BAND_M
        true_speed = (truth_feet[:, 1:, :, :2] - truth_feet[:, :-1, :, :2]).norm(dim=-1) * fps
        stands = (low[:, 1:] & low[:, :-1] & (true_speed < STANCE_MAX_SPEED_MPS)).to(pred_feet.dtype)
    step = pred_feet[:, 1:, :, :2] - pred_feet[:, :-1, :, :2]
    speed = (step.pow(2).sum(-1) + 1e-12).sqrt() * fps  # a plain norm has no gradient at 0
    return (speed * stands).sum() / stands.sum().clamp_min(1.0)


def _feet(x):
    """Ankle roll link positions (..., 2, 3) of features x (..., DIM), through the legs' FK only."""
    from g1_control.generator.fk import fk_torch
    from g1_control.motion.kinematics import default_body_names
    from g1_control.robot import g1

    names = default_body_names()
    pos, _ = fk_torch(x[..., :3], _rot6d_torch(x[..., 3:9]), x[..., 9:38], num_joints=len(g1.LEG_JOINTS))
    return pos[..., [names.index(b) for b in g1.FOOT_BODIES], :]


def model_inputs(batch: dict) -> list:
    return [batch[k] for k in TRAIN_INPUTS]


def loss_fn(model, batch, config: TrainConfig, subsample: bool = True, pos_scale=None):
    import torch

    from g1_control.generator.fk import effectors_torch

    pred, duration = model(*model_inputs(batch))
    truth = batch["truth"]
    b, g = truth.shape[:2]
    pred = pred[:, :g]
    present = batch["present"][:, None, :]
    err = (pred - truth).abs()
    joints = torch.as_tensor(F.JOINT_SLOTS)
    terms = {
        "root": err[..., F.ROOT_POS].mean() * 2.0 + err[..., F.ROOT_ROT].mean(),
        "joints": (err[..., joints] * present[..., joints]).sum() / (present[..., joints].sum() * g).clamp_min(1.0),
        "effectors": err[..., F.EFFECTORS].mean(),
    }
    # FK through 29 joints is the costliest part of a step: a random quarter of the frames suffices.
    pick = torch.randperm(b * g)[: max(1, b * g // 4)] if subsample else torch.arange(b * g)
    flat_p, flat_t = pred.reshape(b * g, -1), truth.reshape(b * g, -1)
    pos, rot, norm = _fk_terms(flat_p[pick], flat_t[pick], pos_scale)
    terms["fk_pos"] = pos * 2.0 * config.fk_weight
    terms["fk_rot"] = rot * config.fk_weight
    if pos_scale is not None:
        terms["fk_pos_norm"] = norm * config.normalized_position_weight
    if config.skate_weight > 0:
        # whole windows (speeds need consecutive frames): a random quarter of them, as above
        rows = torch.randperm(b)[: max(1, b // 4)] if subsample else torch.arange(b)
        with torch.no_grad():
            truth_feet = _feet(truth[rows])
        terms["skate"] = stance_foot_speed(_feet(pred[rows]), truth_feet) * config.skate_weight
    given = batch["gap_given"][:, :g]
    if float(given.sum()) > 0:
        direct = given.clone()
        direct[..., F.EFFECTORS] = 0.0
        goal = (err * direct).sum() / direct.sum().clamp_min(1.0)
        eff_given = given[..., F.EFFECTORS].reshape(b * g, F.NUM_EFFECTORS, 3)[..., 0]
        rows = torch.nonzero(eff_given.sum(-1) > 0)[:, 0]
        if len(rows):
            ppos, prot = _bodies(flat_p[rows])
            eff = effectors_torch(ppos, prot)
            target = flat_t[rows][:, F.EFFECTORS].reshape(-1, F.NUM_EFFECTORS, 3)
            w = eff_given[rows]
            goal = goal + ((eff - target).norm(dim=-1) * w).sum() / w.sum() * 3.0
        terms["goals"] = goal * config.goal_weight
    terms["duration"] = 0.1 * (torch.log(duration + 1.0) - np.log(g + 1.0)).abs().mean()
    return sum(terms.values()), terms


def pad_batch(batch: dict) -> dict:
    """Pad the gap of a sampled batch to an even length (training runs the model's dynamic form:
    only the tokens a gap needs, no gap_len)."""
    from g1_control.generator.learned import PATCH

    g = batch["base"].shape[1]
    if g % PATCH == 0:
        return batch
    out = dict(batch)
    last = batch["context"][:, -1]
    filled = np.where(batch["given"] > 0, batch["target"], last)
    out["base"] = np.concatenate([batch["base"], filled[:, None]], axis=1)
    for k in ("gap_goal", "gap_given"):
        out[k] = np.concatenate([batch[k], np.zeros_like(batch[k][:, :1])], axis=1)
    return out


TRAIN_INPUTS = ("context", "target", "target_given", "base", "gap_goal", "gap_given", "style", "skeleton", "present")


def _to_torch(batch: dict):
    import torch

    out = {}
    for k, v in pad_batch(batch).items():
        if k == "style":
            out[k] = torch.as_tensor(v, dtype=torch.long)
        elif k == "given":
            out["target_given"] = torch.as_tensor(v, dtype=torch.float32)
        elif k != "gap":
            out[k] = torch.as_tensor(np.ascontiguousarray(v), dtype=torch.float32)
    return out


def check_splits(library_root: str | Path | dict | None) -> None:
    """Refuse a library whose train or held-out ('test') split has no clip long enough for a window."""
    from g1_control.motion.library import LibraryError, MotionLibrary, default_library_dir
    from g1_control.training.dataset import CONTEXT_FRAMES, MAX_GAP

    if isinstance(library_root, dict):  # one library per skeleton
        for root in library_root.values():
            check_splits(root)
        return
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


def load_skeletons(skeletons, split: str, library_roots: dict | None = None):
    """Features, style ids and skeleton names of a split over several skeletons' libraries."""
    feats, styles, names = [], [], []
    for sk in skeletons:
        f, s = load_split((library_roots or {}).get(sk), split, sk)
        feats += f
        styles += s
        names += [sk] * len(f)
    return feats, styles, names


def train(out_dir: str | Path, config: TrainConfig, library_root: str | Path | dict | None = None,
          progress: bool = True, records_dir: str | Path | None = None) -> dict:
    """library_root: one library folder (for a single skeleton), {skeleton: folder}, or None
    (each skeleton's default library). out_dir gets what the runtime reads (backbone.onnx, model.json,
    style_stats.json, feedback.npz) and train_config.json; records_dir (default: out_dir) the
    checkpoint backbone.pt, loss_history.json and loss.png."""
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
    records = Path(records_dir) if records_dir is not None else out
    roots = library_root if isinstance(library_root, dict) else (
        {config.skeletons[0]: library_root} if library_root is not None else {})
    feats, styles, names = load_skeletons(config.skeletons, "train", roots)
    sampler = WindowSampler(feats, styles, len(STYLES), seed=config.seed + 1000 * rank, skeletons=names,
                            goal_probability=config.goal_probability, reach_probability=config.reach_probability)
    model_cfg = BackboneConfig(num_styles=len(STYLES), **{"skeletons": tuple(config.skeletons), **config.model})
    model = Backbone(model_cfg)
    samples = [sampler.sample(256) for _ in range(8)]
    stats = np.concatenate([s["truth"].reshape(-1, F.DIM) for s in samples])
    pres = np.concatenate([np.repeat(s["present"], s["truth"].shape[1], axis=0) for s in samples]) > 0
    cnt = np.maximum(pres.sum(0), 1)
    mean = (stats * pres).sum(0) / cnt
    std = np.sqrt((((stats - mean) * pres) ** 2).sum(0) / cnt)
    model.feat_mean.copy_(torch.as_tensor(mean, dtype=torch.float32))
    model.feat_std.copy_(torch.as_tensor(std + 1e-3, dtype=torch.float32))
    from g1_control.generator.fk import fk_numpy

    body_pos, _ = fk_numpy(stats[:, :3], F.rot6d_to_matrix(stats[:, 3:9]), stats[:, 9:38])
    pos_scale = torch.as_tensor(body_pos.std(axis=0) + 1e-3, dtype=torch.float32)
    net = torch.nn.parallel.DistributedDataParallel(model) if world > 1 else model
    opt = torch.optim.AdamW(model.parameters(), lr=config.lr, weight_decay=config.weight_decay)
    clock = [time.perf_counter(), time.process_time()]

    def _progress(s: int) -> float:
        # the cosine ends at the step count or at the time limit, whichever comes first, so a
        # slow (shared) machine still finishes the schedule within the budget
        return min(1.0, max(s / config.steps, (time.process_time() - clock[1]) / config.time_limit_s,
                            (time.perf_counter() - clock[0]) / config.wall_limit_s))

    sched = torch.optim.lr_scheduler.LambdaLR(opt, lambda s: min(1.0, (s + 1) / config.warmup_steps) * 0.5 * (
        1 + np.cos(np.pi * _progress(s))))
    # a fixed validation set from the held-out clips (gaps of 15 and 30 frames)
    vfeats, vstyles, vnames = load_skeletons(config.skeletons, "test", roots)
    vsampler = WindowSampler(vfeats, vstyles, len(STYLES), seed=12345, style_dropout=0.0, skeletons=vnames,
                             goal_probability=config.goal_probability, reach_probability=config.reach_probability)
    history: list[dict] = []
    best: tuple[float, dict[str, torch.Tensor] | None] = (float("inf"), None)

    val_batches = [_to_torch(vsampler.sample(128, gap=g)) for g in (15, 30)]

    def held_out_loss() -> float:
        model.eval()
        with torch.no_grad():
            return float(np.mean([loss_fn(model, b, config, False, pos_scale)[0].item() for b in val_batches]))

    # the untrained model is exactly interpolation (zero-initialized output head): the reference
    initial_val = held_out_loss()
    started = clock[0] = time.perf_counter()
    clock[1] = time.process_time()
    bar = None
    if progress and rank == 0:
        from tqdm import tqdm

        bar = tqdm(total=config.steps, desc="train generator", unit="step", file=sys.stderr)
    step = 0
    for step in range(config.steps):
        batch = _to_torch(sampler.sample(config.batch // world))
        model.train()
        loss, terms = loss_fn(net, batch, config, True, pos_scale)
        opt.zero_grad(set_to_none=True)
        loss.backward()
        torch.nn.utils.clip_grad_norm_(model.parameters(), 1.0)
        opt.step()
        sched.step()
        if bar is not None:
            bar.update()
            bar.set_postfix_str(f"loss {loss.item():.4f}")
        record = {"step": step, "loss": loss.item(), **{k: v.item() for k, v in terms.items()}}
        last = (step == config.steps - 1 or time.process_time() - clock[1] > config.time_limit_s
                or time.perf_counter() - started > config.wall_limit_s)
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
    result = {"steps": step + 1, "wall_s": wall, "cpu_s": time.process_time() - clock[1],
              "initial_val_loss": initial_val, "best_val_loss": best[0], "world_size": world,
              "load_average": os.getloadavg()[0]}
    if rank == 0:
        if best[1] is None:  # every validation loss was NaN
            raise G1ControlError(f"training gave no finite validation loss in {step + 1} steps; nothing saved")
        model.load_state_dict(best[1])
        records.mkdir(parents=True, exist_ok=True)
        save_checkpoint(model, records / "backbone.pt", config)
        (out / "train_config.json").write_text(json.dumps({"train": asdict(config), "model": model_cfg.to_dict(),
                                                           "result": result}, indent=2))
        (records / "loss_history.json").write_text(json.dumps(history))
        plot_losses(history, records / "loss.png")
        export_onnx(model, out / "backbone.onnx")
        write_model_dir(out, config.skeletons, roots)
    if world > 1:
        dist.destroy_process_group()
    return result


def write_model_dir(out: Path, skeletons, roots: dict | None = None) -> None:
    """model.json, style_stats.json and feedback.npz next to a trained model."""
    from g1_control.generator.data import library_dir
    from g1_control.generator.learned import MODEL_FORMAT
    from g1_control.generator.style_stats import write_style_stats
    from g1_control.training.mixtures import write_mixtures

    roots = roots or {}
    (out / "model.json").write_text(json.dumps({"format": MODEL_FORMAT, "skeletons": list(skeletons)}, indent=1))
    base = roots.get("g1_29dof") or (roots.get(skeletons[0]) if len(skeletons) == 1 else None) or library_dir("g1_29dof")
    write_style_stats(base, out / "style_stats.json")
    write_mixtures({sk: roots.get(sk) or library_dir(sk) for sk in skeletons}, out / "feedback.npz")


def save_checkpoint(model, path: Path, config: TrainConfig | None = None) -> None:
    import torch

    torch.save({"model_config": model.config.to_dict(), "state_dict": model.state_dict(),
                "train_config": asdict(config) if config else None}, path)


def load_checkpoint(path: str | Path):
    import torch

    from g1_control.training.backbone import Backbone, BackboneConfig

    blob = torch.load(path, map_location="cpu", weights_only=True)
    config = dict(blob["model_config"])
    config["skeletons"] = tuple(config.get("skeletons", ("g1_29dof",)))
    model = Backbone(BackboneConfig(**config))
    model.load_state_dict(blob["state_dict"])
    model.eval()
    return model


def plot_losses(history: list[dict], path: Path, title: str = "in-betweening backbone") -> None:
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
    ax.set_title(title)
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def export_onnx(model, path: Path) -> None:
    import torch

    from g1_control.generator import skeleton as S
    from g1_control.generator.learned import INPUT_NAMES, PADDED_GAP

    model.eval()
    b, g = 2, PADDED_GAP
    args = (torch.zeros(b, 10, F.DIM), torch.zeros(b, F.DIM), torch.ones(b, F.DIM), torch.zeros(b, g, F.DIM),
            torch.zeros(b, g, F.DIM), torch.zeros(b, g, F.DIM), torch.zeros(b, dtype=torch.long),
            torch.zeros(b, S.NUM_SLOTS * S.DESCRIPTOR_WIDTH), torch.ones(b, F.DIM), torch.full((b,), g))
    axes = {name: {0: "batch"} for name in INPUT_NAMES}
    axes["frames"] = {0: "batch"}
    axes["duration"] = {0: "batch"}
    torch.onnx.export(model, args, str(path), input_names=list(INPUT_NAMES), output_names=["frames", "duration"],
                      dynamo=False, opset_version=17, dynamic_axes=axes)
