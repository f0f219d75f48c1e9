"""Policy metadata checks against the real holosoma ONNX files (fetched once into a cache)."""

import numpy as np
import pytest
import yaml

from g1_control.errors import PolicyMismatchError
from g1_control.robot import g1
from g1_control.trackers.policy_spec import builtin_specs, load_spec


def test_builtin_specs_load_and_match_the_robot():
    for name in ("holosoma_loco_ppo", "holosoma_loco_fastsac"):
        spec = load_spec(name)
        assert spec.joint_names == g1.JOINT_NAMES
        assert spec.observation.dim == 100
        np.testing.assert_allclose(spec.kp, g1.KP_DEFAULT, rtol=1e-6)
        assert spec.command_ranges["lin_vel_x"] == (-1.0, 1.0)


def variant(tmp_path, **changes):
    d = yaml.safe_load(builtin_specs()["holosoma_loco_ppo"].read_text())
    d.update(changes)
    path = tmp_path / "spec.yaml"
    path.write_text(yaml.safe_dump(d))
    return path


def test_swapped_joint_order_is_refused(tmp_path):
    names = list(g1.JOINT_NAMES)
    names[3], names[4] = names[4], names[3]
    with pytest.raises(PolicyMismatchError, match="joint order differs from the G1's at index 3: policy has "
                                                  "left_ankle_pitch_joint, robot has left_knee_joint"):
        load_spec(variant(tmp_path, joint_names=names))


def test_unknown_joint_is_refused(tmp_path):
    names = list(g1.JOINT_NAMES)
    names[0] = "left_hip_joint"
    with pytest.raises(PolicyMismatchError, match="joints the G1 does not have: \\['left_hip_joint'\\]"):
        load_spec(variant(tmp_path, joint_names=names))


def test_observation_size_mismatch_is_refused(tmp_path):
    d = yaml.safe_load(builtin_specs()["holosoma_loco_ppo"].read_text())
    d["observation"]["terms"] = d["observation"]["terms"][:-1]  # drop sin_phase: 98 values
    with pytest.raises(PolicyMismatchError, match="builds 98 values .* takes 100"):
        load_spec(variant(tmp_path, observation=d["observation"]))


def test_gains_that_differ_from_training_are_refused(tmp_path):
    kp = (g1.KP_DEFAULT * 1.5).tolist()
    with pytest.raises(PolicyMismatchError, match="kp in the spec differs from the kp the policy was trained with"):
        load_spec(variant(tmp_path, gains={"kp": kp, "kd": g1.KD_DEFAULT.tolist()}))


def test_unknown_spec_key_and_unknown_name(tmp_path):
    with pytest.raises(PolicyMismatchError, match="spec.yaml: unknown key 'gain'; allowed: onnx, name, kind"):
        load_spec(variant(tmp_path, gain=1))
    with pytest.raises(PolicyMismatchError, match="unknown policy 'nope'"):
        load_spec("nope")


@pytest.mark.parametrize(("change", "message"), [
    ({"rate_hz": "fast"}, "spec.yaml.rate_hz: expected a number, got 'fast'"),
    ({"rate_hz": 0}, "spec.yaml.rate_hz: must be > 0, got 0.0"),
    ({"gains": "metadta"}, "spec.yaml.gains: expected one of 'metadata', 'robot'"),
    ({"gains": {"kp": [1.0]}}, "spec.yaml.gains.kd: required field is missing"),
    ({"phase": {"period_s": 1.0, "offsets_rad": [0.0]}}, "spec.yaml.phase.offsets_rad: expected 2 items, got 1"),
    ({"action": {"scale": [0.25, 0.25]}}, "spec.yaml.action.scale: 2 values for 29 joints"),
    ({"observation": {"terms": ["dof_pos"], "history": 0}}, "spec.yaml.observation.history must be >= 1, got 0"),
    ({"variant": "g1_31dof"}, "spec.yaml.variant: expected one of 'g1_23dof', 'g1_29dof'"),
])
def test_spec_files_are_read_by_the_typed_loader(tmp_path, change, message):
    """The same loader as launch files: every key's type and range checked, the key path named."""
    with pytest.raises(PolicyMismatchError, match=message.replace(".", "\\.").replace("(", "\\(").replace("[", "\\[")):
        load_spec(variant(tmp_path, **change))
