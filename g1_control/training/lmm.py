"""Training learned motion matching (generator/lmm.py; Holden et al. 2020) on the motion library:
`g1 train lmm`.

Stages, on the database built from every training clip (matching features X, poses Y):
1. compressor + decompressor: Y -> z -> D(X, z) ~ Y. Losses: L1 on standardised Y, on the bodies'
   positions through forward kinematics (in the frame's heading frame), on frame-to-frame
   velocities of both (pairs of consecutive frames), and a small L2 on z.
2. stepper: (X_t, z_t) -> (X_{t+1}, z_{t+1}) as residuals, trained by rolling 16 frames forward
   from database frames (z from the trained compressor), L1 on X and z.
3. projector: a noisy query -> the (X, z) of its nearest database frame under the search weights
   (KD-tree nearest neighbours computed on the fly), L1 on X and z.
Then everything is exported as one ONNX graph lmm.onnx: query -> projector -> stepper x 31 ->
decompressor on all 32 frames, with the standardisation constants inside.
"""

from __future__ import annotations

import json
import os
import time
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np


@dataclass
class LmmTrainConfig:
    skeleton: str = "g1_29dof"
    latent: int = 32
    hidden: int = 256
    batch: int = 256
    decompressor_steps: int = 4000
    stepper_steps: int = 2500
    stepper_window: int = 16
    projector_steps: int = 5000
    lr: float = 1e-3
    seed: int = 0
    threads: int = 1
    time_limit_s: float = 25 * 60
    """CPU time of the process over all stages (shares: decompressor 45 %, stepper 30 %, projector 25 %)."""
    wall_limit_s: float = 50 * 60
    """Hard stop on the wall clock whatever the machine's load (same shares)."""
    scale: float = 1.0
    """Multiplies every stage's step count (tests use a tiny fraction)."""


def _mlp(inp: int, hidden: int, out: int, layers: int = 3):
    from torch import nn

    mods, d = [], inp
    for _ in range(layers - 1):
        mods += [nn.Linear(d, hidden), nn.ELU()]
        d = hidden
    mods.append(nn.Linear(d, out))
    return nn.Sequential(*mods)


def build_database(library_root, skeleton: str):
    """X (N, X_DIM), Y (N, Y_DIM) and the (start, end) rows of each clip's run of frames."""
    from g1_control.generator.data import load_split
    from g1_control.generator.lmm import clip_database

    feats, styles = load_split(library_root, "train", skeleton)
    xs, ys, starts = [], [], []
    n = 0
    for f, s in zip(feats, styles):
        x, y = clip_database(f, s)
        if len(x) < 2:
            continue
        starts.append((n, n + len(x)))
        xs.append(x)
        ys.append(y)
        n += len(x)
    return np.concatenate(xs), np.concatenate(ys), starts


def _pose_fk_torch(y):
    """Body positions (N, 30, 3) of poses y (raw units) in their heading frame (root xy at 0)."""
    import torch

    from g1_control.generator.fk import fk_torch
    from g1_control.training.train import _rot6d_torch

    root = torch.cat([torch.zeros(y.shape[0], 2, dtype=y.dtype), y[:, 0:1]], dim=-1)
    pos, _ = fk_torch(root, _rot6d_torch(y[:, 1:7]), y[:, 7:36])
    return pos


def train_lmm(out_dir: str | Path, config: LmmTrainConfig, library_root=None, progress: bool = True,
              records_dir: str | Path | None = None) -> dict:
    """out_dir gets what the runtime reads (lmm.onnx, model.json) and train_config.json; records_dir
    (default: out_dir) the checkpoint lmm.pt, loss_history.json and loss.png."""
    import torch
    from torch import nn

    from g1_control.generator.lmm import MAX_STEPS, X_DIM, X_GROUPS, X_WEIGHTS, Y_DIM

    torch.manual_seed(config.seed)
    torch.set_num_threads(max(1, config.threads))
    rng = np.random.default_rng(config.seed)
    cpu0 = time.process_time()
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    records = Path(records_dir) if records_dir is not None else out
    records.mkdir(parents=True, exist_ok=True)
    started = time.perf_counter()
    budget = {"decompressor": 0.45, "stepper": 0.3, "projector": 0.25}
    x_np, y_np, runs = build_database(library_root, config.skeleton)
    timings = {"database_s": time.perf_counter() - started}
    n = len(x_np)
    valid_next = np.zeros(n, dtype=bool)  # frame i has a successor in the same run
    run_end = np.zeros(n, dtype=int)
    for a, b in runs:
        valid_next[a:b - 1] = True
        run_end[a:b] = b
    x_mean, x_std = x_np.mean(0), x_np.std(0) + 1e-3
    y_mean, y_std = y_np.mean(0), y_np.std(0) + 1e-3
    style = X_GROUPS["style"]
    x_mean[style], x_std[style] = 0.0, 1.0
    X = torch.as_tensor((x_np - x_mean) / x_std, dtype=torch.float32)
    Y = torch.as_tensor((y_np - y_mean) / y_std, dtype=torch.float32)
    ym, ys = torch.as_tensor(y_mean, dtype=torch.float32), torch.as_tensor(y_std, dtype=torch.float32)
    history: dict[str, list] = {"decompressor": [], "stepper": [], "projector": []}
    h, lat = config.hidden, config.latent

    def steps(k: int) -> int:
        return max(2, int(k * config.scale))

    def bar(total, desc):
        from tqdm import tqdm

        return tqdm(total=total, desc=desc, unit="step", disable=not progress)

    class Deadline:
        """Past this stage's share of the CPU budget or of the wall limit."""

        def __init__(self, name):
            self.cpu = time.process_time() + budget[name] * config.time_limit_s
            self.wall = time.perf_counter() + budget[name] * config.wall_limit_s

        def passed(self) -> bool:
            return time.process_time() > self.cpu or time.perf_counter() > self.wall

    def fit(name: str, params, total: int, batch_loss) -> None:
        """One stage: AdamW with a cosine schedule for `total` steps or until the stage's deadline;
        batch_loss() draws a batch and returns (loss, extra figures for the history)."""
        opt = torch.optim.AdamW(params, lr=config.lr, weight_decay=1e-4)
        sched = torch.optim.lr_scheduler.CosineAnnealingLR(opt, total)
        deadline = Deadline(name)
        with bar(total, f"lmm {name}") as b:
            for step in range(total):
                loss, extra = batch_loss()
                opt.zero_grad(set_to_none=True)
                loss.backward()
                opt.step()
                sched.step()
                b.update()
                history[name].append({"step": step, "loss": loss.item(), **extra})
                if deadline.passed():
                    break

    # ------------------------------------------------------------------ 1. compressor + decompressor
    compressor = _mlp(Y_DIM, h, lat)
    decompressor = _mlp(X_DIM + lat, h, Y_DIM)
    pairs = np.flatnonzero(valid_next)

    def decompressor_loss():
        i = torch.as_tensor(rng.choice(pairs, config.batch))
        j = i + 1
        z_i, z_j = compressor(Y[i]), compressor(Y[j])
        y_i = decompressor(torch.cat([X[i], z_i], -1))
        y_j = decompressor(torch.cat([X[j], z_j], -1))
        rec = (y_i - Y[i]).abs().mean() + (y_j - Y[j]).abs().mean()
        vel = ((y_j - y_i) - (Y[j] - Y[i])).abs().mean()
        raw_p, raw_t = y_i * ys + ym, Y[i] * ys + ym
        fk = (_pose_fk_torch(raw_p) - _pose_fk_torch(raw_t)).abs().mean() * 10.0
        reg = 0.01 * (z_i ** 2).mean()
        return rec + vel + fk + reg, {"rec": rec.item(), "fk": fk.item()}

    fit("decompressor", list(compressor.parameters()) + list(decompressor.parameters()),
        steps(config.decompressor_steps), decompressor_loss)
    compressor.eval()
    decompressor.eval()
    with torch.no_grad():
        Z = torch.cat([compressor(Y[k:k + 8192]) for k in range(0, n, 8192)])
        recon = torch.cat([decompressor(torch.cat([X[k:k + 8192], Z[k:k + 8192]], -1)) for k in range(0, n, 8192)])
        decompress_err = float(((recon - Y) * ys).abs().mean())
    timings["decompressor_s"] = time.perf_counter() - started - sum(timings.values())
    # ------------------------------------------------------------------ 2. stepper
    stepper = _mlp(X_DIM + lat, h, X_DIM + lat)
    w = config.stepper_window
    starts_ok = np.flatnonzero(run_end - np.arange(n) > w)

    def stepper_loss():
        i0 = rng.choice(starts_ok, config.batch // 4)
        x, z = X[torch.as_tensor(i0)], Z[torch.as_tensor(i0)]
        loss = 0.0
        for k in range(1, w):
            d = stepper(torch.cat([x, z], -1))
            x, z = x + d[:, :X_DIM], z + d[:, X_DIM:]
            idx = torch.as_tensor(i0 + k)
            loss = loss + (x - X[idx]).abs().mean() + (z - Z[idx]).abs().mean()
        return loss / (w - 1), {}

    fit("stepper", stepper.parameters(), steps(config.stepper_steps), stepper_loss)
    stepper.eval()
    timings["stepper_s"] = time.perf_counter() - started - sum(timings.values())
    # ------------------------------------------------------------------ 3. projector
    weights = np.ones(X_DIM)
    for name, sl in X_GROUPS.items():
        weights[sl] = X_WEIGHTS[name] / np.sqrt(sl.stop - sl.start)
    Wt = torch.as_tensor(weights, dtype=torch.float32)
    db = X * Wt
    db_sq = (db * db).sum(-1)

    def nearest(q: torch.Tensor) -> torch.Tensor:
        # exact nearest neighbours by brute force (a KD-tree degrades to it in 44 dimensions)
        qw = q * Wt
        return (db_sq[None, :] - 2.0 * qw @ db.T).argmin(dim=1)

    projector = _mlp(X_DIM, h, X_DIM + lat, layers=4)

    def projector_loss():
        rows = rng.integers(0, n, config.batch)
        noise = rng.normal(size=(config.batch, X_DIM)) * rng.uniform(0.0, 1.0, size=(config.batch, 1))
        noise[:, style] = 0.0  # the style is always known exactly
        q = X[torch.as_tensor(rows)] + torch.as_tensor(noise, dtype=torch.float32)
        with torch.no_grad():
            nn_idx = nearest(q)
        pred = projector(q)
        loss = ((pred[:, :X_DIM] - X[nn_idx]) * Wt).abs().mean() * 5.0 + (pred[:, X_DIM:] - Z[nn_idx]).abs().mean()
        return loss, {}

    fit("projector", projector.parameters(), steps(config.projector_steps), projector_loss)
    projector.eval()
    wall = time.perf_counter() - started
    timings["projector_s"] = wall - sum(timings.values())

    # ------------------------------------------------------------------ export
    class Rollout(nn.Module):
        def __init__(self):
            super().__init__()
            self.projector, self.stepper, self.decompressor = projector, stepper, decompressor
            for name, arr in (("x_mean", x_mean), ("x_std", x_std), ("y_mean", y_mean), ("y_std", y_std)):
                self.register_buffer(name, torch.as_tensor(arr, dtype=torch.float32))

        def forward(self, query):
            q = (query - self.x_mean) / self.x_std
            p = self.projector(q)
            x, z = p[:, :X_DIM], p[:, X_DIM:]
            xs, zs = [x], [z]
            for _ in range(MAX_STEPS - 1):
                d = self.stepper(torch.cat([x, z], -1))
                x, z = x + d[:, :X_DIM], z + d[:, X_DIM:]
                xs.append(x)
                zs.append(z)
            xz = torch.cat([torch.stack(xs, 1), torch.stack(zs, 1)], -1)
            y = self.decompressor(xz)
            return y * self.y_std + self.y_mean

    torch.save({"config": asdict(config), "x_mean": x_mean, "x_std": x_std, "y_mean": y_mean, "y_std": y_std,
                "compressor": compressor.state_dict(), "decompressor": decompressor.state_dict(),
                "stepper": stepper.state_dict(), "projector": projector.state_dict()}, records / "lmm.pt")
    model = Rollout().eval()
    torch.onnx.export(model, (torch.zeros(2, X_DIM),), str(out / "lmm.onnx"), input_names=["query"],
                      output_names=["poses"], dynamo=False, opset_version=17,
                      dynamic_axes={"query": {0: "batch"}, "poses": {0: "batch"}})
    sizes = {name: sum(p.numel() for p in m.parameters()) for name, m in
             (("compressor", compressor), ("decompressor", decompressor), ("stepper", stepper),
              ("projector", projector))}
    result = {"wall_s": wall, "cpu_s": time.process_time() - cpu0, "load_average": os.getloadavg()[0],
              "database_frames": n, "decompressor_l1_raw": decompress_err,
              "stage_steps": {k: len(v) for k, v in history.items()}, "parameters": sizes,
              "timings_s": timings}
    (out / "model.json").write_text(json.dumps({"format": 1, "skeletons": [config.skeleton]}, indent=1))
    (out / "train_config.json").write_text(json.dumps({"train": asdict(config), "result": result}, indent=2))
    (records / "loss_history.json").write_text(json.dumps(history))
    _plot(history, records / "loss.png")
    return result


def _plot(history: dict, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 3, figsize=(12, 3.5))
    for ax, (name, rows) in zip(axes, history.items()):
        if rows:
            loss = np.array([r["loss"] for r in rows])
            k = max(1, len(loss) // 100)
            ax.plot(np.convolve(loss, np.ones(k) / k, mode="valid"))
        ax.set_title(f"LMM {name}")
        ax.set_yscale("log")
        ax.set_xlabel("step")
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


class LmmNetworks:
    """The four trained networks of an lmm.pt checkpoint, on raw (unstandardised) features."""

    def __init__(self, path: str | Path):
        import torch

        from g1_control.generator.lmm import X_DIM, Y_DIM

        blob = torch.load(path, map_location="cpu", weights_only=False)
        c = blob["config"]
        h, lat = c["hidden"], c["latent"]
        self.compressor = _mlp(Y_DIM, h, lat)
        self.decompressor = _mlp(X_DIM + lat, h, Y_DIM)
        self.stepper = _mlp(X_DIM + lat, h, X_DIM + lat)
        self.projector = _mlp(X_DIM, h, X_DIM + lat, layers=4)
        for name in ("compressor", "decompressor", "stepper", "projector"):
            getattr(self, name).load_state_dict(blob[name])
            getattr(self, name).eval()
        self.x_mean, self.x_std, self.y_mean, self.y_std = (blob[k] for k in ("x_mean", "x_std", "y_mean", "y_std"))

    def compress(self, y: np.ndarray) -> np.ndarray:
        import torch

        with torch.no_grad():
            return self.compressor(torch.as_tensor((y - self.y_mean) / self.y_std, dtype=torch.float32)).numpy()

    def decompress(self, x: np.ndarray, z: np.ndarray) -> np.ndarray:
        import torch

        xs = torch.as_tensor((x - self.x_mean) / self.x_std, dtype=torch.float32)
        with torch.no_grad():
            y = self.decompressor(torch.cat([xs, torch.as_tensor(z, dtype=torch.float32)], -1)).numpy()
        return y * self.y_std + self.y_mean
