"""The estimator's model is the legs (base -> soles), which every G1 variant has in full: the same
estimator serves the 23-DoF G1 and the 29-DoF one, and a variant's missing joints never enter it."""

from __future__ import annotations

import numpy as np
import pytest

from g1_control.estimation.estimator import StateEstimator
from g1_control.robot import g1
from g1_control.sim.mujoco_backend import MujocoBackend, MujocoConfig


@pytest.mark.parametrize("variant", list(g1.VARIANTS.values()), ids=lambda v: v.name)
def test_every_joint_the_estimator_models_is_a_joint_of_every_variant(variant):
    names = tuple(StateEstimator().model.names[2:])
    assert names == tuple(g1.JOINT_NAMES[i] for i in g1.LEG_JOINTS)
    assert {g1.JOINT_INDEX[n] for n in names} <= set(variant.active_joints)


def test_the_estimate_on_the_23dof_robot_matches_its_ground_truth_standing_still():
    backend = MujocoBackend(MujocoConfig(variant="g1_23dof"))
    backend.reset()
    estimator = StateEstimator()
    for _ in range(100):
        backend.step(0.002)
        estimate = estimator.update(backend.read_state())
    state = backend.read_state()
    assert np.abs(estimate.base_linvel_w_mps - state.base_linvel_w_mps).max() < 0.1
    # pelvis height above the lower sole: the simulator's pelvis height less the sole's few millimetres
    assert estimate.pelvis_height_m == pytest.approx(state.base_pos_w_m[2], abs=0.03)
