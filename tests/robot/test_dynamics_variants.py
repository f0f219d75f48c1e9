"""The controller's dynamics of a G1 variant (WbcModel(variant)): the variant's own model, in the
29-DoF G1's coordinates, checked against MuJoCo's model of the same variant (built independently from
the same URDF by the simulator)."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from g1_control.robot import g1
from g1_control.robot.dynamics import WbcModel
from g1_control.sim.mujoco_backend import MujocoBackend, MujocoConfig


def _state(variant: g1.Variant, seed: int = 3):
    """A random joint configuration and velocity of `variant` (0 where it has no joint), base upright at rest."""
    rng = np.random.default_rng(seed)
    q = g1.DEFAULT_Q_RAD + rng.uniform(-0.3, 0.3, g1.NUM_JOINTS)
    q = np.clip(q, g1.Q_MIN_RAD, g1.Q_MAX_RAD) * variant.active_mask
    dq = rng.uniform(-1.0, 1.0, g1.NUM_JOINTS) * variant.active_mask
    return q, dq


@pytest.mark.parametrize("variant", [g1.G1_23DOF, g1.G1_29DOF_LOCKED_WAIST, g1.G1_29DOF])
def test_mass_matrix_and_bias_are_mujocos_of_the_same_variant(variant):
    model = WbcModel(variant)
    backend = MujocoBackend(MujocoConfig(variant=variant.name))
    m, d = backend.model, backend.data
    q, dq = _state(variant)
    active = list(variant.active_joints)
    d.qpos[:7] = [0.1, -0.2, 0.75, 1.0, 0.0, 0.0, 0.0]
    d.qpos[7:] = q[active]
    d.qvel[:] = 0.0
    d.qvel[6:] = dq[active]
    mujoco.mj_forward(m, d)
    mass = np.zeros((m.nv, m.nv))
    mujoco.mj_fullM(m, d, mass)
    model.update(np.concatenate([[0.1, -0.2, 0.75, 0.0, 0.0, 0.0, 1.0], q]), np.concatenate([np.zeros(6), dq]))
    kept = np.concatenate([np.arange(6), 6 + np.array(active)])
    np.testing.assert_allclose(model.mass_matrix[np.ix_(kept, kept)], mass, atol=1e-9)
    np.testing.assert_allclose(model.bias[kept], d.qfrc_bias, atol=1e-9)
    np.testing.assert_allclose(model.com_m, d.subtree_com[1], atol=1e-9)


def test_a_locked_joint_is_decoupled_from_everything():
    model = WbcModel(g1.G1_23DOF)
    q, dq = _state(g1.G1_23DOF)
    model.update(np.concatenate([[0.0, 0.0, 0.75, 0.0, 0.0, 0.0, 1.0], q]), np.concatenate([np.zeros(6), dq]))
    locked = [6 + i for i in range(g1.NUM_JOINTS) if i not in g1.G1_23DOF.active_joints]
    assert len(locked) == 6
    sub = model.mass_matrix[np.ix_(locked, locked)]
    np.testing.assert_array_equal(sub, np.eye(6))
    others = np.setdiff1d(np.arange(model.nv), locked)
    assert not model.mass_matrix[np.ix_(locked, others)].any() and not model.bias[locked].any()
    assert not model.com_jac[:, locked].any() and not model.contact_jac_local[:, locked].any()
    assert not model.frame(model.hand_ids[1]).jac_w[:, locked].any()
    # the 29-DoF model does use those joints: the torso moves with waist pitch
    full = WbcModel()
    full.update(np.concatenate([[0.0, 0.0, 0.75, 0.0, 0.0, 0.0, 1.0], q]), np.concatenate([np.zeros(6), dq]))
    assert np.abs(full.com_jac[:, locked]).max() > 0.01


def test_the_variant_models_weigh_the_same_and_share_frames():
    a, b = WbcModel(), WbcModel(g1.G1_23DOF)
    assert a.mass_kg == pytest.approx(b.mass_kg) and b.nv == a.nv == 35
    assert b.dynamics_model.nv == 29
    assert [f.name for f in a.model.frames] == [f.name for f in b.dynamics_model.frames]


def test_the_dex3_model_is_mujocos_with_the_fingers_held():
    """With the fingers at rest, the dynamics of the body's coordinates are the hand robot's with
    the fingers locked: MuJoCo's mass matrix and bias restricted to those coordinates."""
    model = WbcModel(hands="dex3")
    backend = MujocoBackend(MujocoConfig(hands="dex3"))
    m, d = backend.model, backend.data
    q, dq = _state(g1.G1_29DOF)
    body = [m.jnt_dofadr[m.joint(n).id] for n in g1.JOINT_NAMES]
    d.qpos[:7] = [0.0, 0.0, 0.75, 1.0, 0.0, 0.0, 0.0]
    d.qpos[[m.jnt_qposadr[m.joint(n).id] for n in g1.JOINT_NAMES]] = q
    d.qvel[:] = 0.0
    d.qvel[body] = dq
    mujoco.mj_forward(m, d)
    mass = np.zeros((m.nv, m.nv))
    mujoco.mj_fullM(m, d, mass)
    kept = np.concatenate([np.arange(6), body])
    model.update(np.concatenate([[0.0, 0.0, 0.75, 0.0, 0.0, 0.0, 1.0], q]), np.concatenate([np.zeros(6), dq]))
    np.testing.assert_allclose(model.mass_matrix, mass[np.ix_(kept, kept)], atol=1e-9)
    np.testing.assert_allclose(model.bias, d.qfrc_bias[kept], atol=1e-9)
    assert model.mass_kg == pytest.approx(34.394, abs=1e-3) and WbcModel().mass_kg == pytest.approx(33.341, abs=1e-3)


@pytest.mark.parametrize("variant", [g1.G1_23DOF, g1.G1_29DOF])
def test_hand_masses_add_the_loads_inertia_at_the_hands(variant):
    """With point masses at the hands (a held box's inertia), M ddq + bias grows by m J^T a_hand for any
    ddq (a_hand the hand's classical acceleration): the hands' forces include -m a_hand. A 23-DoF
    variant's locked joints (its wrists) are at 0 here, so the full model's hand kinematics are its own."""
    import pinocchio as pin

    plain, loaded = WbcModel(variant), WbcModel(variant)
    loaded.hand_masses_kg[:] = (1.5, 2.0)
    q, dq = _state(variant, seed=5)
    qf = np.concatenate([[0.1, -0.2, 0.75, 0.0, 0.0, 0.0, 1.0], q])
    v = np.concatenate([[0.2, -0.1, 0.05, 0.3, -0.2, 0.4], dq])
    plain.update(qf, v)
    loaded.update(qf, v)
    rng = np.random.default_rng(1)
    ddq = rng.uniform(-2.0, 2.0, plain.nv) * np.concatenate([np.ones(6), variant.active_mask])
    # the hands' accelerations for this ddq, from the full 29-DoF model's own kinematics
    full = WbcModel(g1.G1_29DOF)
    data = full.model.createData()
    pin.forwardKinematics(full.model, data, qf, v, ddq)
    pin.updateFramePlacements(full.model, data)
    expected = plain.mass_matrix @ ddq + plain.bias
    for fid, mass in zip(full.hand_ids, loaded.hand_masses_kg):
        jac = pin.computeFrameJacobian(full.model, data, qf, fid, pin.LOCAL_WORLD_ALIGNED)[:3]
        acc = pin.getFrameClassicalAcceleration(full.model, data, fid, pin.LOCAL_WORLD_ALIGNED).linear
        expected += mass * jac.T @ acc
    kept = np.concatenate([np.arange(6), 6 + np.array(variant.active_joints)])  # locked rows stay decoupled
    np.testing.assert_allclose((loaded.mass_matrix @ ddq + loaded.bias)[kept], expected[kept], atol=1e-8)
    assert np.abs(loaded.mass_matrix - plain.mass_matrix).max() > 0.1  # the load is felt


def test_hand_moments_enter_the_dynamics_as_the_hands_angular_jacobian_transposed():
    """A held bottle's weight acts off the hand point: its moment m there joins the bias as -J_ang^T m."""
    import pinocchio as pin

    plain, loaded = WbcModel(), WbcModel()
    loaded.hand_moments_w_nm[1] = (0.1, -0.2, 0.05)
    q, dq = _state(g1.G1_29DOF, seed=3)
    qf = np.concatenate([[0.0, 0.1, 0.76, 0.0, 0.0, 0.0, 1.0], q])
    v = np.concatenate([[0.1, 0.0, 0.0, 0.0, 0.2, 0.0], dq])
    plain.update(qf, v)
    loaded.update(qf, v)
    data = plain.model.createData()
    jac = pin.computeFrameJacobian(plain.model, data, qf, plain.hand_ids[1], pin.LOCAL_WORLD_ALIGNED)[3:]
    np.testing.assert_allclose(loaded.bias, plain.bias - jac.T @ loaded.hand_moments_w_nm[1], atol=1e-9)
    assert np.abs(loaded.bias - plain.bias)[6 + 22:].max() > 0.01  # the right arm feels it
