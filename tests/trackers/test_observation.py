import numpy as np
import pytest

from g1_control.errors import PolicyMismatchError
from g1_control.trackers.observation import ObservationBuilder, ObservationSpec


def values(base=0.0):
    return {
        "actions": np.full(29, base + 1.0), "base_ang_vel": np.array([1.0, 2.0, 3.0]) + base,
        "command_ang_vel": np.array([0.5]), "command_lin_vel": np.array([0.1, 0.2]),
        "cos_phase": np.array([1.0, -1.0]), "sin_phase": np.array([0.0, 0.5]),
        "dof_pos": np.arange(29.0), "dof_vel": np.full(29, 10.0), "projected_gravity": np.array([0, 0, -1.0]),
    }


def test_terms_concatenate_in_listed_order_with_scales():
    spec = ObservationSpec.from_dict({"terms": [{"name": "base_ang_vel", "scale": 0.25}, "command_ang_vel",
                                                {"name": "dof_vel", "scale": 0.05}]})
    obs = ObservationBuilder(spec).build(values())
    assert obs.shape == (1, 3 + 1 + 29) and obs.dtype == np.float32
    np.testing.assert_allclose(obs[0, :3], [0.25, 0.5, 0.75])
    assert obs[0, 3] == 0.5
    np.testing.assert_allclose(obs[0, 4:], 0.5)


def test_holosoma_layout_is_100_values_with_dof_pos_at_offset_37():
    terms = ["actions", {"name": "base_ang_vel", "scale": 0.25}, "command_ang_vel", "command_lin_vel",
             "cos_phase", "dof_pos", {"name": "dof_vel", "scale": 0.05}, "projected_gravity", "sin_phase"]
    spec = ObservationSpec.from_dict({"terms": terms})
    assert spec.dim == 100
    obs = ObservationBuilder(spec).build(values())[0]
    # actions 29 + ang vel 3 + cmd ang 1 + cmd lin 2 + cos 2 = 37
    np.testing.assert_allclose(obs[37:66], np.arange(29.0))
    np.testing.assert_allclose(obs[-2:], [0.0, 0.5])


def test_history_stacks_per_term_oldest_first():
    spec = ObservationSpec.from_dict({"terms": ["command_ang_vel", "command_lin_vel"], "history": 3})
    builder = ObservationBuilder(spec)
    v = values()
    first = builder.build(v).copy()
    np.testing.assert_allclose(first[0], [0.5, 0.5, 0.5, 0.1, 0.2, 0.1, 0.2, 0.1, 0.2])
    v["command_ang_vel"] = np.array([0.7])
    obs = builder.build(v)[0]
    np.testing.assert_allclose(obs[:3], [0.5, 0.5, 0.7])


def test_unknown_term_is_named():
    with pytest.raises(PolicyMismatchError, match="unknown observation term 'base_lin_vel'"):
        ObservationSpec.from_dict({"terms": ["actions", "base_lin_vel"]})


def test_wrong_term_width_is_refused():
    builder = ObservationBuilder(ObservationSpec.from_dict({"terms": ["base_ang_vel"]}))
    with pytest.raises(PolicyMismatchError, match="'base_ang_vel' has shape"):
        builder.build({"base_ang_vel": np.zeros(2)})
