"""The compiled per-tick kernels (g1_control/ik/kernels.py) against pinocchio's own functions."""

import numpy as np
import pinocchio as pin
import pytest

from g1_control.ik import kernels
from g1_control.ik.configuration import Configuration
from g1_control.robot import description, g1


def _rotations() -> list[np.ndarray]:
    """Random axes at angles from zero through tiny and ordinary up to (and exactly) pi."""
    rng = np.random.default_rng(7)
    out = []
    for angle in (0.0, 1e-12, 1e-9, 1e-6, 1e-4, 1e-2, 0.5, 1.5, 2.5, 3.0, np.pi - 1e-2, np.pi - 2e-3,
                  np.pi - 1e-4, np.pi - 1e-7, np.pi):
        for _ in range(4):
            axis = rng.standard_normal(3)
            out.append(pin.exp3(angle * axis / np.linalg.norm(axis)))
    return out


def test_log3_matches_pinocchio_at_every_angle():
    got = np.empty(3)
    for rot in _rotations():
        kernels.log3(rot, got)
        expected = pin.log3(rot)
        if np.linalg.norm(expected) > np.pi - 1e-6:  # at pi, w and -w are the same rotation
            assert np.allclose(pin.exp3(got), rot, atol=1e-9)
            assert abs(np.linalg.norm(got) - np.linalg.norm(expected)) < 1e-9
        else:
            np.testing.assert_allclose(got, expected, atol=1e-9)


def test_jlog3_matches_pinocchio_at_every_angle():
    w, got = np.empty(3), np.empty((3, 3))
    for rot in _rotations():
        kernels.log3(rot, w)
        if np.linalg.norm(w) > np.pi - 1e-3:
            continue  # Jlog3 is unbounded at pi (pinocchio and we agree on the formula, not the blow-up)
        kernels.jlog3(w, got)
        np.testing.assert_allclose(got, pin.Jlog3(rot), atol=1e-8)


def test_quaternion_to_matrix_normalises_like_pinocchio():
    rng = np.random.default_rng(3)
    out = np.empty((3, 3))
    for _ in range(20):
        q = rng.standard_normal(4) * rng.uniform(0.1, 10.0)  # not unit length on purpose
        kernels.quat_to_matrix(*q, out)
        expected = pin.Quaternion(*q).normalized().toRotationMatrix()  # pinocchio takes (w, x, y, z) here
        np.testing.assert_allclose(out, expected, atol=1e-12)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_frame_rows_equal_the_pinocchio_frame_jacobian_formula(seed):
    rng = np.random.default_rng(seed)
    quat = rng.standard_normal(4)
    conf = Configuration(description.pinocchio_q(rng.standard_normal(3), quat / np.linalg.norm(quat),
                                                 rng.uniform(g1.Q_MIN_RAD * 0.6, g1.Q_MAX_RAD * 0.6)))
    names = ["pelvis", "torso_link", "left_rubber_hand", "right_ankle_roll_link", "left_toe", "head_link"]
    fids = [conf.frame_id(n) for n in names]
    orientation = np.array([True, True, False, True, False, True])
    targets = np.empty((len(fids), 7))
    rot_targets = []
    for k in range(len(fids)):
        rot = pin.exp3(rng.standard_normal(3))
        rot_targets.append(rot)
        q = pin.Quaternion(rot)
        targets[k] = [*rng.standard_normal(3), q.w, q.x, q.y, q.z]
    sizes = np.where(orientation, 6, 3)
    starts = np.concatenate([[0], np.cumsum(sizes)[:-1]]).astype(np.int64)
    jac = np.full((int(sizes.sum()), conf.nv), np.nan)
    err = np.full(int(sizes.sum()), np.nan)
    kernels.frame_rows(conf.joint_jacobians_w, conf.placements(fids), targets, conf.support_masks(tuple(fids)),
                       orientation, starts, jac, err)
    for k, fid in enumerate(fids):
        placement = conf.frame_placement(fid)
        full = pin.getFrameJacobian(conf.model, conf.data, fid, pin.LOCAL_WORLD_ALIGNED)
        r = starts[k]
        np.testing.assert_allclose(err[r:r + 3], placement.translation - targets[k, :3], atol=1e-12)
        np.testing.assert_allclose(jac[r:r + 3], full[:3], atol=1e-12)
        if orientation[k]:
            rel = rot_targets[k].T @ placement.rotation
            np.testing.assert_allclose(err[r + 3:r + 6], pin.log3(rel), atol=1e-9)
            np.testing.assert_allclose(jac[r + 3:r + 6], pin.Jlog3(rel) @ placement.rotation.T @ full[3:], atol=1e-9)
    assert np.isfinite(jac).all() and np.isfinite(err).all()  # every row written
