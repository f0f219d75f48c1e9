"""The foot-skating term of the backbone's loss: hand-built feet with a known answer (still feet
cost nothing, feet sliding at v cost v where the true foot stands and nothing where it swings),
its gradient, and the term through loss_fn's forward kinematics on a standing pose."""

import numpy as np
import pytest
import torch

from g1_control.generator import evaluation as E
from g1_control.generator import features as F
from g1_control.generator.fk import fk_numpy
from g1_control.motion.kinematics import default_body_names
from g1_control.robot import g1
from g1_control.training.train import STANCE_MAX_SPEED_MPS, TrainConfig, _feet, loss_fn, stance_foot_speed

FPS = 30.0
STANCE_Z = E.STANCE_ANKLE_Z_M
SWING_Z = E.STANCE_ANKLE_Z_M + E.CONTACT_BAND_M + 0.05


def _feet_track(frames: int, z=(STANCE_Z, STANCE_Z), v_mps=((0.0, 0.0), (0.0, 0.0)), batch: int = 2):
    """(batch, frames, 2, 3) ankles: each foot at height z[side], moving at v_mps[side] (x, y)."""
    t = np.arange(frames) / FPS
    out = np.zeros((batch, frames, 2, 3))
    for side in range(2):
        out[:, :, side, 0] = 0.1 + v_mps[side][0] * t
        out[:, :, side, 1] = (0.12 if side == 0 else -0.12) + v_mps[side][1] * t
        out[:, :, side, 2] = z[side]
    return torch.as_tensor(out, dtype=torch.float32)


def test_still_feet_on_standing_truth_cost_nothing():
    truth = _feet_track(20)
    assert stance_foot_speed(truth.clone(), truth, FPS).item() == pytest.approx(0.0, abs=1e-4)


def test_feet_sliding_at_v_where_the_truth_stands_cost_v():
    truth = _feet_track(20)
    pred = _feet_track(20, v_mps=((0.15, 0.2), (0.15, 0.2)))  # 0.25 m/s horizontally
    assert stance_foot_speed(pred, truth, FPS).item() == pytest.approx(0.25, rel=1e-3)
    # vertical motion is not skating
    lift = truth.clone()
    lift[..., 2] += torch.linspace(0.0, 0.02, 20)[None, :, None]
    assert stance_foot_speed(lift, truth, FPS).item() == pytest.approx(0.0, abs=1e-4)


def test_only_the_standing_foot_is_judged():
    # left foot stands in the truth, right foot swings: the prediction's right foot may move
    truth = _feet_track(20, z=(STANCE_Z, SWING_Z))
    pred = _feet_track(20, v_mps=((0.3, 0.0), (1.0, 0.0)))
    assert stance_foot_speed(pred, truth, FPS).item() == pytest.approx(0.3, rel=1e-3)
    # a true foot that is low but fast (pushing off, sliding) is not a stance foot either
    fast = _feet_track(20, v_mps=((STANCE_MAX_SPEED_MPS + 0.1, 0.0), (0.0, 0.0)))
    assert stance_foot_speed(pred, fast, FPS).item() == pytest.approx(1.0, rel=1e-3)
    # no standing foot anywhere: nothing to judge, zero (not NaN)
    flying = _feet_track(20, z=(SWING_Z, SWING_Z))
    assert stance_foot_speed(pred, flying, FPS).item() == 0.0


def test_gradient_steps_stop_the_sliding_foot():
    truth = _feet_track(20)
    pred = _feet_track(20, v_mps=((0.2, 0.0), (0.0, 0.0))).requires_grad_(True)
    before = stance_foot_speed(pred, truth, FPS)
    before.backward()
    assert torch.isfinite(pred.grad).all() and pred.grad[..., 0, :2].abs().sum() > 0
    assert pred.grad[..., 2].abs().max() == 0  # height is not the term's business
    with torch.no_grad():
        after = stance_foot_speed(pred - 1e-3 * pred.grad / pred.grad.norm(), truth, FPS)
    assert after < before


def _standing_features(frames: int, root_vx_mps: float = 0.0) -> torch.Tensor:
    """(1, frames, DIM) default standing pose with its lowest ankle at stance height; the whole body
    translated at root_vx_mps along x (feet sliding with it)."""
    q = np.tile(g1.DEFAULT_Q_RAD, (frames, 1))
    rot = np.tile(np.eye(3), (frames, 1, 1))
    pos = np.zeros((frames, 3))
    pos[:, 2] = g1.DEFAULT_PELVIS_HEIGHT_M
    body, _ = fk_numpy(pos[:1], rot[:1], q[:1])
    feet = [default_body_names().index(b) for b in g1.FOOT_BODIES]
    pos[:, 2] -= body[0, feet, 2].min() - STANCE_Z
    pos[:, 0] = root_vx_mps * np.arange(frames) / FPS
    feats = F.world_features(pos, rot, q, np.zeros((frames, F.NUM_EFFECTORS, 3)))
    return torch.as_tensor(feats[None], dtype=torch.float32)


def test_loss_fn_skate_term_through_forward_kinematics():
    truth = _standing_features(16)
    feet = _feet(truth)
    assert feet.shape == (1, 16, 2, 3)
    assert feet[..., 2].max().item() < STANCE_Z + E.CONTACT_BAND_M  # both feet stand in the truth
    batch = {"truth": truth, "present": torch.ones(1, F.DIM), "gap_given": torch.zeros(1, 16, F.DIM)}

    def terms_for(pred, weight):
        def model(*_inputs):
            return pred, torch.full((1,), 16.0)

        batch.update({k: torch.zeros(1) for k in ("context", "target", "target_given", "base", "gap_goal", "style",
                                                    "skeleton")})
        return loss_fn(model, batch, TrainConfig(skate_weight=weight), subsample=False)[1]

    assert terms_for(truth.clone(), 0.1)["skate"].item() == pytest.approx(0.0, abs=1e-4)
    sliding = terms_for(_standing_features(16, root_vx_mps=0.2), 0.1)["skate"].item()
    assert sliding == pytest.approx(0.1 * 0.2, rel=1e-3)
    assert "skate" not in terms_for(_standing_features(16, root_vx_mps=0.2), 0.0)


def test_cli_refuses_a_negative_skate_weight(capsys):
    from g1_control.cli.main import main

    assert main(["train", "generator", "--skate-weight", "-1", "--library", "/nonexistent"]) == 1
    assert "--skate-weight must be >= 0" in capsys.readouterr().err
