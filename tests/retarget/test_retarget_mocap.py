import json
from pathlib import Path

import numpy as np
import pytest

from g1_control.ik.exceptions import IKError
from g1_control.motion.exceptions import InvalidClipError, UnknownJointError
from g1_control.motion.human import HumanMotion
from g1_control.motion.skeletons import LAFAN1, SMPLH
from g1_control.retarget.metrics import compute_metrics
from g1_control.retarget.mocap import (
    MocapRetargetConfig,
    MocapRetargeter,
    frame_from_left_up,
    load_joint_map,
    prepare_targets,
)
from tests.motion.test_motion_skeletons import lafan1_joint_map


def demo_root(monkeypatch) -> Path:
    """The holosoma demo data from the user cache (fetched from the registry on first use)."""
    from g1_control import assets

    return assets.fetch("holosoma-demo-mocap", quiet=True) / "holosoma_retargeting" / "demo_data"


def test_omomo_slice_retargets_within_the_acceptance_thresholds(monkeypatch):
    from g1_control.motion.formats.joint_positions import read_omomo_pt

    motion = read_omomo_pt(demo_root(monkeypatch) / "OMOMO_new" / "sub3_largebox_003.pt")
    short = HumanMotion(motion.positions_w_m[:90], motion.joint_names, motion.fps, motion.height_m, motion.source)
    clip = MocapRetargeter(MocapRetargetConfig(warmup_iterations=30)).retarget(short)
    assert clip.num_frames == 90 and clip.fps == 30.0
    m = compute_metrics(clip)
    assert m.joint_limit_violations == 0 and m.velocity_limit_violations == 0
    assert m.penetration_fraction <= 0.01 and m.sliding_fraction <= 0.02
    assert clip.contacts.any(), "the performer walks: some stance must be found"
    # the G1 pelvis follows the human pelvis across the room (scaled by height)
    scale = 1.32 / motion.height_m
    human = short.joint("Pelvis")[:, :2] * scale
    travel = np.linalg.norm(human[-1] - human[0])
    robot_travel = np.linalg.norm(clip.root_pos_w_m[-1, :2] - clip.root_pos_w_m[0, :2])
    assert travel > 0.2 and abs(robot_travel - travel) < 0.1 * travel + 0.02


def test_stance_feet_are_put_at_the_sole_height_from_the_data():
    t = 60
    pos = np.zeros((t, len(LAFAN1.joints), 3))
    idx = {n: i for i, n in enumerate(LAFAN1.joints)}
    layout = {"Hips": (0, 0, 0.95), "LeftUpLeg": (0, 0.1, 0.9), "RightUpLeg": (0, -0.1, 0.9), "Spine2": (0, 0, 1.3),
              "LeftArm": (0, 0.2, 1.4), "RightArm": (0, -0.2, 1.4), "LeftFoot": (0, 0.1, 0.10),
              "RightFoot": (0, -0.1, 0.10), "LeftToe": (0.15, 0.1, 0.04), "RightToe": (0.15, -0.1, 0.04)}
    for name, p in layout.items():
        pos[:, idx[name]] = p
    motion = HumanMotion(pos, LAFAN1.joints, 30.0, 1.75, "standing")
    sole = {"left_ankle_roll_link": 0.035, "right_ankle_roll_link": 0.035, "left_toe": 0.0, "right_toe": 0.0}
    targets = prepare_targets(motion, LAFAN1, MocapRetargetConfig(), sole)
    assert targets.contacts.all()
    np.testing.assert_allclose(targets.keypoints_w_m["left_toe"][:, 2], 0.0, atol=1e-12)
    np.testing.assert_allclose(targets.keypoints_w_m["right_ankle_roll_link"][:, 2], 0.035, atol=1e-12)


def test_per_limb_scale_stretches_the_limb_from_its_root():
    t = 5
    pos = np.random.default_rng(0).standard_normal((t, len(SMPLH.joints), 3)) * 0.1 + [0, 0, 1.0]
    motion = HumanMotion(pos, SMPLH.joints, 30.0, 1.32, "random")
    sole = {}
    plain = prepare_targets(motion, SMPLH, MocapRetargetConfig(), sole)
    long_arm = prepare_targets(motion, SMPLH, MocapRetargetConfig(limb_scale={"left_arm": 1.5}), sole)
    root = plain.keypoints_w_m["left_shoulder_roll_link"]
    np.testing.assert_allclose(long_arm.keypoints_w_m["left_shoulder_roll_link"], root)
    np.testing.assert_allclose(long_arm.keypoints_w_m["left_rubber_hand"] - root,
                               1.5 * (plain.keypoints_w_m["left_rubber_hand"] - root))
    np.testing.assert_allclose(long_arm.keypoints_w_m["right_rubber_hand"], plain.keypoints_w_m["right_rubber_hand"])


def test_bad_configs_and_inputs_are_named():
    with pytest.raises(IKError, match="unknown limbs \\['tail'\\]"):
        MocapRetargetConfig(limb_scale={"tail": 2.0}).validate()
    pos = np.zeros((4, 3, 3))
    with pytest.raises(UnknownJointError, match="match no known skeleton"):
        MocapRetargeter().retarget(HumanMotion(pos, ("a", "b", "c"), 30.0, None, "odd.npy"))
    pos = np.zeros((4, len(LAFAN1.joints), 3))
    pos[2, 3, 1] = np.nan
    with pytest.raises(InvalidClipError, match="'bad.bvh': NaN or inf at frame 2"):
        MocapRetargeter().retarget(HumanMotion(pos, LAFAN1.joints, 30.0, None, "bad.bvh"))


def test_frame_from_left_up_is_a_rotation_with_y_left():
    rot = frame_from_left_up(np.array([[0.0, 2.0, 0.0]]), np.array([[0.1, 0.0, 1.0]]))[0]
    np.testing.assert_allclose(rot.T @ rot, np.eye(3), atol=1e-12)
    np.testing.assert_allclose(rot[:, 1], [0, 1, 0], atol=1e-12)
    assert np.linalg.det(rot) == pytest.approx(1.0)


def test_omomo_box_contacts_are_kept_through_retargeting(monkeypatch):
    """OMOMO box lifting: the file carries the box's pose; the G1's hands stay at the box on the
    frames where the performer's hands are on it."""
    from g1_control.motion.formats.joint_positions import read_omomo_pt

    motion = read_omomo_pt(demo_root(monkeypatch) / "OMOMO_new" / "sub3_largebox_003.pt")
    assert motion.object is not None and motion.object.shape.name == "largebox"
    short = HumanMotion(motion.positions_w_m[:120], motion.joint_names, motion.fps, motion.height_m, motion.source,
                        motion.object.take(slice(0, 120)))
    clip = MocapRetargeter().retarget(short)
    assert clip.object is not None and clip.object.num_frames == clip.num_frames
    scale = 1.32 / motion.height_m
    np.testing.assert_allclose(clip.object.pos_w_m, short.object.pos_w_m * scale, atol=1e-9)
    m = compute_metrics(clip)
    assert m.object_contact_frames > 100, "the performer holds the box with both hands for most of the slice"
    assert m.object_contact_preserved_fraction >= 0.95 and m.max_object_penetration_m < 0.02
    assert m.passes()


def test_climbing_feet_stay_on_and_out_of_the_boxes(monkeypatch):
    """Climb seq 1 (the performer steps onto a box): the boxes come with the data and the G1's feet
    neither sink into their tops nor pass through their sides (before the scene was known to the
    IK, 36 % of this clip's frames had a foot > 1 cm inside a box)."""
    from g1_control.motion.formats.joint_positions import read_npy

    path = next((demo_root(monkeypatch) / "climb" / "mocap_climb_seq_1").glob("*.npy"))
    motion = read_npy(path)
    assert len(motion.scene) == 2
    short = HumanMotion(motion.positions_w_m[:1600], motion.joint_names, motion.fps, motion.height_m, motion.source,
                        scene=motion.scene)
    clip = MocapRetargeter().retarget(short)
    assert len(clip.scene) == 2
    climbed = clip.body_pos_w_m[:, clip.body_index("left_ankle_roll_link"), 2].max()
    assert climbed > 0.3, "the slice includes the step up"
    m = compute_metrics(clip)
    assert m.penetration_fraction <= 0.01 and m.max_penetration_m < 0.02, m
    assert m.passes()


def test_joint_map_with_unknown_g1_frames_names_them(tmp_path):
    bad, good = tmp_path / "map.json", tmp_path / "good.json"
    bad.write_text(json.dumps(lafan1_joint_map({"LeftHand": "left_claw"})))
    with pytest.raises(UnknownJointError, match=r"map.json: joint map targets G1 frames that do not exist: \['left_claw'\]"):
        load_joint_map(bad)
    good.write_text(json.dumps(lafan1_joint_map()))
    assert load_joint_map(good).frame_map == LAFAN1.frame_map
