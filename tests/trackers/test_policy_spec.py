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
    with pytest.raises(PolicyMismatchError, match="unknown keys \\['gain'\\]"):
        load_spec(variant(tmp_path, gain=1))
    with pytest.raises(PolicyMismatchError, match="unknown policy 'nope'"):
        load_spec("nope")
