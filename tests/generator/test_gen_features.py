"""Frame features, canonical frames and batched FK of the generator."""

import numpy as np
import pytest

from g1_control import rotations as quat
from g1_control.generator import features as F
from g1_control.generator.fk import fk_numpy, fk_torch
from g1_control.motion.kinematics import default_body_names, forward_kinematics
from g1_control.robot import g1


def _random_frames(n, seed=0):
    rng = np.random.default_rng(seed)
    root = rng.normal(size=(n, 3)) + [0, 0, 0.75]
    q = quat.normalize(rng.normal(size=(n, 4)))
    joints = rng.uniform(g1.Q_MIN_RAD, g1.Q_MAX_RAD, size=(n, 29))
    return root, q, joints


def test_batched_fk_matches_pinocchio():
    root, q, joints = _random_frames(5)
    pos_ref, quat_ref = forward_kinematics(root, q, joints, default_body_names())
    pos, rot = fk_numpy(root, quat.to_matrix(q), joints)
    assert np.abs(pos - pos_ref).max() < 1e-9
    q_ours = quat.from_matrix(rot)
    q_ref = quat_ref * np.sign(quat_ref[..., :1] + 1e-15)
    assert np.abs(q_ours - q_ref).max() < 1e-9


def test_torch_fk_matches_numpy_and_has_gradients():
    import torch

    root, q, joints = _random_frames(3, seed=1)
    rot = quat.to_matrix(q)
    j = torch.tensor(joints, requires_grad=True)
    pos_t, _ = fk_torch(torch.tensor(root), torch.tensor(rot), j)
    pos_n, _ = fk_numpy(root, rot, joints)
    assert np.abs(pos_t.detach().numpy() - pos_n).max() < 1e-12
    pos_t[:, -1].sum().backward()  # right wrist yaw link depends on the right arm joints
    assert j.grad[:, 22:29].abs().sum() > 0 and j.grad[:, 0:6].abs().sum() == 0


def test_canonicalize_puts_reference_frame_at_origin_facing_x_and_inverts():
    root, q, joints = _random_frames(4, seed=2)
    q[:, 1:3] *= 0.1  # mostly upright
    q = quat.normalize(q)
    rot = quat.to_matrix(q)
    pos, brot = fk_numpy(root, rot, joints)
    eff = F.effectors_from_bodies(pos, brot, default_body_names())
    feats = F.world_features(root, rot, joints, eff)
    canon = F.canonicalize(feats, 2)
    assert np.allclose(canon[2, 0:2], 0.0) and np.isclose(canon[2, 2], root[2, 2])
    assert abs(F.yaw_of_matrix(F.rot6d_to_matrix(canon[2, F.ROOT_ROT]))) < 1e-9
    origin, yaw = F.reference_of(feats[2])
    back = F.transform(canon, origin, yaw, inverse=True)
    assert np.allclose(back, feats, atol=1e-12)
    # the per-replan fast path agrees with the general transform both ways
    assert np.allclose(F.transform_one(feats, origin, float(yaw)), canon, atol=1e-12)
    assert np.allclose(F.transform_one(canon, origin, float(yaw), inverse=True), feats, atol=1e-12)
    # effectors stay consistent with FK after the transform
    assert np.allclose(F.fix_effectors(canon)[:, F.EFFECTORS], canon[:, F.EFFECTORS], atol=1e-9)


def test_rot6d_orthonormalizes_and_matrix_to_quat_agrees_with_scipy():
    rng = np.random.default_rng(3)
    rot = quat.to_matrix(quat.normalize(rng.normal(size=(50, 4))))
    noisy = np.concatenate([rot[:, :, 0], rot[:, :, 1]], -1) + rng.normal(size=(50, 6)) * 0.01
    m = F.rot6d_to_matrix(noisy)
    assert np.allclose(m @ np.swapaxes(m, 1, 2), np.eye(3), atol=1e-10)
    assert np.allclose(np.linalg.det(m), 1.0)
    ours = np.array([F.matrix_to_quat(r) for r in rot])
    assert np.allclose(ours, quat.from_matrix(rot), atol=1e-12)


def test_head_point_is_on_the_torso_above_the_shoulders():
    pos, brot = fk_numpy(np.array([[0, 0, 0.75]]), np.eye(3)[None], np.zeros((1, 29)))
    eff = F.effectors_from_bodies(pos, brot, default_body_names())
    torso = pos[0, default_body_names().index("torso_link")]
    head = eff[0, F.EFFECTOR_BODIES.index("head")]
    assert 0.35 < head[2] - torso[2] < 0.45 and abs(head[1]) < 1e-3  # centre of the head, on the mid-plane


@pytest.mark.parametrize("bad", [np.zeros((2, F.DIM)), np.zeros((1, 2, F.DIM - 1))])
def test_inbetweener_refuses_bad_shapes(bad):
    from g1_control.generator.baselines import InterpolationInbetweener
    from g1_control.generator.inbetween import InbetweenError

    with pytest.raises(InbetweenError, match="context must have shape"):
        InterpolationInbetweener().infill(bad, np.zeros((1, F.DIM)), np.ones((1, F.DIM), bool), 5, np.zeros(1, int))
