"""One generator for every G1 variant: skeletons, variant libraries, and picking (or refusing) a
model by the launch file's robot."""

import json

import numpy as np
import pytest

from g1_control.errors import LaunchFileError
from g1_control.generator import features as F
from g1_control.generator import skeleton as S
from g1_control.generator.learned import OnnxInbetweener, check_skeleton, prepare_inputs
from g1_control.launch.schema import parse_launch
from g1_control.robot import g1


def test_skeletons_differ_in_the_joints_they_have_and_share_the_body_geometry():
    s29, s23, sh = (S.skeleton(n) for n in S.SKELETONS)
    assert s29.present.sum() == 29 and s23.present.sum() == 23 and sh.present.sum() == 43
    dropped = np.flatnonzero(s29.present & ~s23.present)
    assert {g1.JOINT_NAMES[i] for i in dropped} == {"waist_roll_joint", "waist_pitch_joint", "left_wrist_pitch_joint",
                                                    "left_wrist_yaw_joint", "right_wrist_pitch_joint",
                                                    "right_wrist_yaw_joint"}
    d29, d23, dh = (s.descriptor() for s in (s29, s23, sh))
    assert np.array_equal(d29[:29], dh[:29])  # the hand URDF's body joints are placed as the 29-DoF's
    assert not d23[dropped].any() and not d29[29:].any() and dh[29:, 0].all()
    assert np.all(sh.q_min[29:] <= 0) and np.all(sh.q_max[29:] >= 0) and not s29.q_max[29:].any()
    with pytest.raises(S.SkeletonError, match="unknown generator skeleton 'g1_12dof'"):
        S.skeleton("g1_12dof")


def test_finger_mirror_swaps_sides_and_matches_the_urdf_limits():
    perm, sign = S.finger_mirror()
    lo, hi = S.finger_limits()
    assert np.array_equal(perm[perm], np.arange(14))
    assert [S.FINGER_JOINTS[i].split("_", 1)[1] for i in perm] == [n.split("_", 1)[1] for n in S.FINGER_JOINTS]
    # the mirror image of a joint's range is the other side's range
    m_lo = np.where(sign > 0, lo[perm], -hi[perm])
    m_hi = np.where(sign > 0, hi[perm], -lo[perm])
    assert np.allclose(m_lo, lo) and np.allclose(m_hi, hi)


def test_robot_variant_picks_the_skeleton():
    assert S.skeleton_for_robot("g1_29dof") == "g1_29dof"
    assert S.skeleton_for_robot("g1_23dof") == "g1_23dof"
    assert S.skeleton_for_robot("g1_29dof", "dex3") == "g1_29dof_with_hand"
    with pytest.raises(S.SkeletonError, match="no model for robot variant 'g1_29dof_locked_waist'"):
        S.skeleton_for_robot("g1_29dof_locked_waist")
    with pytest.raises(S.SkeletonError, match="Dex3 hands are modelled on the 29-DoF G1 only"):
        S.skeleton_for_robot("g1_23dof", "dex3")


@pytest.fixture()
def model_29_only(tmp_path):
    (tmp_path / "backbone.onnx").write_bytes(b"")
    (tmp_path / "model.json").write_text(json.dumps({"format": 2, "skeletons": ["g1_29dof"]}))
    return tmp_path / "backbone.onnx"


def test_a_model_for_another_variant_is_refused_with_a_clear_error(model_29_only):
    check_skeleton(model_29_only, "g1_29dof")
    with pytest.raises(S.SkeletonError, match=r"trained for g1_29dof; the robot is g1_23dof.*g1 train generator"):
        OnnxInbetweener(model_29_only, skeleton="g1_23dof")


def test_launch_file_refuses_a_model_that_does_not_serve_its_robot(model_29_only):
    good = {"name": "x", "generator": {"type": "backbone", "model": str(model_29_only)},
            "input": {"type": "scripted", "timeline": [{"duration_s": 1.0}]}}
    parse_launch(good)
    bad = json.loads(json.dumps(good))
    bad["backend"] = {"expected_variant": "g1_23dof"}
    with pytest.raises(LaunchFileError, match=r"generator.model: .* trained for g1_29dof; the robot is g1_23dof"):
        parse_launch(bad)
    hands = json.loads(json.dumps(good))
    hands["backend"] = {"hands": "dex3"}
    with pytest.raises(LaunchFileError, match="the robot is g1_29dof_with_hand"):
        parse_launch(hands)
    locked = json.loads(json.dumps(good))
    locked["backend"] = {"expected_variant": "g1_29dof_locked_waist"}
    with pytest.raises(LaunchFileError, match="no model for robot variant 'g1_29dof_locked_waist'"):
        parse_launch(locked)
    velocity = {**good, "generator": {"type": "velocity"}, "backend": {"expected_variant": "g1_29dof_locked_waist"}}
    parse_launch(velocity)  # generators without a model do not care


def test_model_inputs_carry_the_skeleton_and_pad_the_gap():
    ctx = np.zeros((2, 10, F.DIM))
    feed = prepare_inputs(ctx, ctx[:, -1], np.ones((2, F.DIM), bool), 15, "g1_23dof")
    from g1_control.generator.learned import PADDED_GAP

    # constant-shape graph: the gap is padded to PADDED_GAP frames and gap_len says how many are real
    assert feed["base"].shape == (2, PADDED_GAP, F.DIM) and feed["gap_goal"].shape == (2, PADDED_GAP, F.DIM)
    assert PADDED_GAP > 15 and (feed["gap_len"] == 15).all()
    assert not feed["gap_given"][:, 15:].any()
    assert np.allclose(feed["skeleton"][0], S.skeleton("g1_23dof").descriptor().reshape(-1))
    present = feed["present"][0] > 0
    assert not present[F.JOINT_SLOTS[g1.JOINT_INDEX["waist_roll_joint"]]] and not present[F.FINGERS].any()
    assert present[F.ROOT].all() and present[F.EFFECTORS].all()


def test_builder_picks_the_skeleton_from_the_launch_file(monkeypatch):
    from g1_control.launch import builder

    seen = {}

    def fake(kind, **kwargs):
        seen.update(kwargs, kind=kind)
        return None

    monkeypatch.setattr("g1_control.generator.factory.make_generator", fake)
    launch = parse_launch({"name": "x", "generator": {"type": "backbone"}, "backend": {"hands": "dex3"},
                           "input": {"type": "scripted", "timeline": [{"duration_s": 1.0}]}})
    builder.make_generator(launch)
    assert seen["skeleton"] == "g1_29dof_with_hand" and seen["kind"] == "backbone"
    launch.backend.hands, launch.backend.expected_variant = "none", "g1_23dof"
    builder.make_generator(launch)
    assert seen["skeleton"] == "g1_23dof"
