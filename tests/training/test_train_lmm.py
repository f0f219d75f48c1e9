"""Learned motion matching: the database representation, training on a tiny library, the
components' round trip, and the exported runtime graph."""

import json

import numpy as np
import pytest

from g1_control.generator import evaluation as E
from g1_control.generator import features as F
from g1_control.generator.data import load_split
from g1_control.generator.lmm import (
    X_DIM,
    Y_DIM,
    LearnedMotionMatchingInbetweener,
    clip_database,
    frames_from_poses,
    pose_features,
)
from g1_control.library.builder import LibraryConfig, build_library
from g1_control.training.lmm import LmmNetworks, LmmTrainConfig, build_database, train_lmm


@pytest.fixture(scope="module")
def library(tmp_path_factory):
    out = tmp_path_factory.mktemp("lib")
    build_library(out, LibraryConfig(rollout_seconds=12.0, rollouts_per_style=1, rollout_styles=("default",),
                                     dance=False, demo=False, clip_seconds=4.0), progress=False)
    return out


@pytest.fixture(scope="module")
def trained(library, tmp_path_factory):
    out = tmp_path_factory.mktemp("lmm")
    config = LmmTrainConfig(hidden=64, latent=16, decompressor_steps=600, stepper_steps=60, projector_steps=150,
                            batch=128)
    return out, train_lmm(out, config, library, progress=False)


def test_pose_representation_round_trips_to_frames(library):
    feats, styles = load_split(library, "train")
    clip = feats[0]
    x, y = clip_database(clip, styles[0])
    assert x.shape[1] == X_DIM and y.shape[1] == Y_DIM and len(x) == len(clip) - 31
    # poses -> integrated frames reproduce the clip (root path from the velocities, the rest exactly)
    back = frames_from_poses(y[None], clip[1:2, 0:2], np.array([np.arctan2(clip[1, 4], clip[1, 3])]))[0]
    truth = clip[1:1 + len(y)]
    assert np.abs(back[:, F.JOINT_SLOTS] - truth[:, F.JOINT_SLOTS]).max() < 1e-9
    assert np.abs(back[:, F.EFFECTORS] - truth[:, F.EFFECTORS]).max() < 1e-6
    assert np.abs(back[:, 0:3] - truth[:, 0:3]).max() < 1e-6
    assert np.allclose(pose_features(truth[:-1], truth[1:]), y[:-1], atol=1e-9)


def test_decompress_of_compress_reproduces_poses(trained, library):
    out, result = trained
    nets = LmmNetworks(out / "lmm.pt")
    x, y, _ = build_database(library, "g1_29dof")
    rec = nets.decompress(x, nets.compress(y))
    err = np.abs(rec - y).mean(axis=0) / nets.y_std
    # within 0.25 standard deviations per pose feature on average (predicting the mean: ~0.8)
    assert err.mean() < 0.25, err.mean()
    joints = np.abs(rec[:, 7:36] - y[:, 7:36]).mean()
    assert joints < 0.05  # rad
    assert result["parameters"]["decompressor"] > 0 and result["wall_s"] < 30 * 60


def test_exported_lmm_plays_from_the_context_and_lands_on_the_target(trained, library):
    out, _ = trained
    assert json.loads((out / "model.json").read_text())["skeletons"] == ["g1_29dof"]
    m = LearnedMotionMatchingInbetweener(out)
    feats, styles = load_split(library, "test")
    w = E.make_windows(feats, styles, 20, stride=10)
    mask = np.ones((len(w.frames), F.DIM), bool)
    pred = m.infill(w.context, w.target, mask, 20, w.style)
    assert pred.shape == (len(w.frames), 20, F.DIM) and np.all(np.isfinite(pred))
    # the splice: the first frame continues the context, the last approaches the target
    assert np.abs(pred[:, 0, F.JOINTS] - w.context[:, -1, F.JOINTS]).mean() < 0.05
    assert np.linalg.norm(pred[:, -1, 0:2] - w.target[:, 0:2], axis=1).mean() < 0.05
