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
from g1_control.generator import features as F
from g1_control.generator import skeleton as S
from g1_control.generator.baselines import InterpolationInbetweener
from g1_control.generator.learned import INPUT_NAMES, SHIPPED_DIR, OnnxInbetweener, TorchInbetweener, prepare_inputs
from g1_control.library.builder import LibraryConfig, build_library
from g1_control.robot import g1
from g1_control.training.train import TrainConfig, load_checkpoint, load_split, train

TINY = {"d_model": 16, "layers": 1, "heads": 2, "ff": 32, "duration_hidden": 8}
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
    result = train(out, TrainConfig(steps=60, batch=32, eval_every=20, warmup_steps=5, lr=3e-3, model=TINY,
                                    reach_probability=0.0),
                   library, progress=False, records_dir=out / "records")
    return out, result


def test_training_writes_checkpoint_onnx_config_plot_and_learns(trained):
    out, result = trained
    for name in ("backbone.onnx", "train_config.json", "style_stats.json", "model.json", "feedback.npz"):
        assert (out / name).is_file(), name
    # what the runtime never reads goes to the records folder, not next to the model
    for name in ("backbone.pt", "loss_history.json", "loss.png"):
        assert (out / "records" / name).is_file() and not (out / name).exists(), name
    history = json.loads((out / "records" / "loss_history.json").read_text())
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
    mask = rng.random((len(w.frames), F.DIM)) < 0.5
    mask[:, :9] = True
    goal_mask = rng.random((len(w.frames), gap, F.DIM)) < 0.05
    args = (w.context, w.target, mask, gap, w.style)
    onnx = OnnxInbetweener(out / "backbone.onnx")
    torch_model = TorchInbetweener(load_checkpoint(out / "records" / "backbone.pt"))
    for m in (onnx, torch_model):
        m.set_goals(w.truth, goal_mask)
    a, b = onnx.infill(*args), torch_model.infill(*args)
    assert a.shape == (len(w.frames), gap, F.DIM)
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
    from g1_control.training import TRAINING_RECORDS_DIR

    onnx_path, ckpt = SHIPPED_DIR / "backbone.onnx", TRAINING_RECORDS_DIR / "generator" / "backbone.pt"
    assert ckpt.stat().st_size <= 20 * 2**20 and onnx_path.stat().st_size <= 20 * 2**20
    config = json.loads((SHIPPED_DIR / "train_config.json").read_text())
    assert config["result"]["wall_s"] <= 30 * 60
    assert json.loads((SHIPPED_DIR / "model.json").read_text())["skeletons"] == list(S.SKELETONS)
    ctx = np.zeros((1, 10, F.DIM))
    ctx[..., 2], ctx[..., 3], ctx[..., 7] = 0.75, 1.0, 1.0
    for sk in S.SKELETONS:
        out = OnnxInbetweener(onnx_path, skeleton=sk).infill(ctx, ctx[:, -1], np.ones((1, F.DIM), bool), 20,
                                                             np.zeros(1, int))
        assert out.shape == (1, 20, F.DIM) and np.all(np.isfinite(out))
        absent = ~F.present_mask(S.skeleton(sk).present)
        assert not out[..., absent].any()  # joints a skeleton lacks stay exactly 0


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
    model = load_checkpoint(out / "records" / "backbone.pt")
    rng = np.random.default_rng(1)
    ctx = rng.normal(size=(3, 10, F.DIM))
    tgt = rng.normal(size=(3, F.DIM))
    given = np.ones((3, F.DIM), bool)
    durations = []
    for gap in (10, 26):
        feed = prepare_inputs(ctx, tgt, given, gap, "g1_29dof")
        with torch.no_grad():
            durations.append(model(*[torch.as_tensor(feed[k]) for k in INPUT_NAMES])[1])
    assert torch.allclose(*durations)  # the same context and target: the same predicted duration


def test_goal_masks_cover_subsets_and_never_give_missing_joints():
    from g1_control.training.dataset import WindowSampler

    rng = np.random.default_rng(0)
    clips = [np.cumsum(rng.normal(scale=0.01, size=(80, F.DIM)), axis=0) for _ in range(4)]
    sampler = WindowSampler(clips, [0] * 4, 11, skeletons=["g1_23dof", "g1_23dof", "g1_29dof", "g1_29dof"],
                            goal_probability=1.0, reach_probability=0.0)
    b = sampler.sample(400, gap=20)
    given, goals, present = b["given"] > 0, b["gap_given"] > 0, b["present"] > 0
    assert not (given & ~present).any() and not (goals & ~present[:, None, :]).any()
    is23 = ~present[:, F.JOINT_SLOTS[g1.JOINT_INDEX["waist_roll_joint"]]]
    assert 0.3 < is23.mean() < 0.7  # both skeletons drawn, equally weighted
    kinds = {tuple(row) for row in given.astype(int)}
    assert len(kinds) > 50  # subsets, not a few fixed masks
    full = given.all(axis=1) | (given == present).all(axis=1)
    assert 0.15 < full.mean() < 0.45
    per_window = goals.any(axis=2).sum(axis=1)
    assert per_window.min() >= 1 and per_window.max() <= 2  # one or two goal frames each
    hand = F.effector_slice("right_wrist_yaw_link")
    assert goals[..., hand].any() and (goals[..., hand].all(-1) == goals[..., hand].any(-1)).all()  # xyz together
    # goal values are the truth at the goal frames, 0 elsewhere
    assert np.allclose(b["gap_goal"][goals], b["truth"][goals]) and not b["gap_goal"][~goals].any()


def test_reaching_augmentation_moves_arms_after_the_context_consistently_with_fk():
    from g1_control.training.dataset import WindowSampler

    rng = np.random.default_rng(1)
    base = np.zeros((90, F.DIM))
    base[:, 0] = np.linspace(0, 1, 90)
    base[:, 2], base[:, 3], base[:, 7] = 0.75, 1.0, 1.0
    base[:, F.JOINTS] = g1.DEFAULT_Q_RAD
    body = (np.arange(F.DIM) >= 9) & (np.arange(F.DIM) < F.FINGERS.start)
    clips = [F.fix_effectors(base + rng.normal(scale=1e-3, size=base.shape) * body)]
    plain = WindowSampler(clips, [0], 11, seed=3, reach_probability=0.0, goal_probability=0.0).sample(64, gap=24)
    moved = WindowSampler(clips, [0], 11, seed=3, reach_probability=1.0, goal_probability=0.0).sample(64, gap=24)
    assert np.allclose(moved["context"], plain["context"])  # reaches start after the context
    arms = F.JOINT_SLOTS[list(g1.ARM_JOINTS)]
    change = np.abs(moved["truth"][..., arms] - plain["truth"][..., arms]).max(axis=(1, 2))
    assert (change > 0.2).mean() > 0.9
    legs = F.JOINT_SLOTS[list(g1.LEG_JOINTS)]
    assert np.allclose(moved["truth"][..., legs], plain["truth"][..., legs])
    frames = np.concatenate([moved["context"], moved["truth"]], axis=1)
    assert np.abs(F.fix_effectors(frames)[..., F.EFFECTORS] - frames[..., F.EFFECTORS]).max() < 1e-6
    hand = F.effector_slice("right_wrist_yaw_link")
    lo = np.concatenate([moved["truth"][:, -1, hand], moved["context"][:, -1, hand]])
    assert np.ptp(lo[:, 2]) > 0.3  # hands all over the workspace, not at the style postures
    assert (moved["given"][:, hand].all(axis=1)).mean() > 0.3  # the reaching hand is usually a goal


def test_goals_on_gap_frames_steer_the_trained_model(trained, library):
    out, _ = trained
    feats, styles = load_split(library, "test")
    w = E.make_windows(feats, styles, 16, stride=10)
    m = OnnxInbetweener(out / "backbone.onnx")
    mask = np.zeros((len(w.frames), F.DIM), bool)
    mask[:, :9] = True
    plain = m.infill(w.context, w.target, mask, 16, w.style)
    goal_mask = np.zeros((len(w.frames), 16, F.DIM), bool)
    goal_mask[:, 8, F.effector_slice("right_wrist_yaw_link")] = True
    moved = w.truth.copy()
    moved[:, 8, F.effector_slice("right_wrist_yaw_link")] += 0.3
    m.set_goals(moved, goal_mask)
    steered = m.infill(w.context, w.target, mask, 16, w.style)
    assert np.abs(steered - plain).max() > 1e-4  # the goal token changes the plan
    m.infill(w.context, w.target, mask, 16, w.style)  # goals are consumed by one call
    assert np.allclose(m.infill(w.context, w.target, mask, 16, w.style), plain, atol=1e-6)
