"""Motion library builder: styles, rollouts, dance extraction, split, cache."""

import json

import numpy as np
import pytest

from g1_control.generator.styles import ROLLOUT_STYLES, STYLES, style_id
from g1_control.library.builder import LibraryConfig, build_library, cut
from g1_control.motion.library import LibraryError, MotionLibrary
from g1_control.robot import g1


def test_there_are_at_least_eight_styles_and_every_pose_is_within_limits():
    assert len(set(STYLES)) == len(STYLES) >= 8
    for style in ROLLOUT_STYLES.values():
        for t in np.linspace(0, 3, 31):
            q = style.pose(t)
            assert np.all(q >= g1.Q_MIN_RAD) and np.all(q <= g1.Q_MAX_RAD), style.name
            assert np.allclose(q[list(g1.LEG_JOINTS)], g1.DEFAULT_Q_RAD[list(g1.LEG_JOINTS)])
    with pytest.raises(ValueError, match="unknown style 'moonwalk'; known styles: default"):
        style_id("moonwalk")


@pytest.fixture(scope="module")
def tiny_library(tmp_path_factory):
    out = tmp_path_factory.mktemp("lib")
    # gate off: these tests count cutting, mirroring and splitting (the gate: test_library_gate.py)
    config = LibraryConfig(rollout_seconds=5.0, rollouts_per_style=1, rollout_styles=("default", "carry"),
                           dance=False, demo=False, clip_seconds=1.0, gate=False)
    return build_library(out, config, progress=False), config


def test_build_records_physics_rollouts_cut_mirrored_and_split_by_clip(tiny_library):
    lib, _ = tiny_library
    assert lib.styles == ["carry", "default"]
    entries = lib.entries
    assert len(entries) == 2 * 5 * 2  # 2 styles x 5 one-second pieces x (original + mirror)
    by_name = {e.name: e for e in entries}
    for e in entries:
        if e.mirrored:
            assert by_name[e.name.removesuffix("_mirror")].split == e.split  # mirrors never leak
    assert {e.split for e in entries} == {"train", "test"}
    test = lib.select("test")
    assert all(e.name.split("_")[-1 if not e.mirrored else -2] == "02" for e in test)
    clip = lib.load(lib.select("train", ("carry",))[0])
    assert clip.style == "carry" and clip.fps == 30.0 and clip.num_frames == 30
    # the rollout is physics: the pelvis stays near standing height and the feet touch the ground
    assert 0.5 < clip.root_pos_w_m[:, 2].min() and clip.root_pos_w_m[:, 2].max() < 0.85
    feet = clip.body_pos_w_m[:, [clip.body_index(b) for b in g1.FOOT_BODIES], 2]
    assert 0.0 < feet.min() < 0.06
    carry = g1.JOINT_INDEX["left_shoulder_pitch_joint"]
    assert clip.joint_pos_rad[:, carry].mean() < g1.DEFAULT_Q_RAD[carry] - 0.3  # the style's arm pose


def test_build_is_cached_and_forced_rebuild_refreshes(tiny_library):
    lib, config = tiny_library
    index = lib.root / "index.json"
    stamp = index.stat().st_mtime_ns
    again = build_library(lib.root, config, progress=False)
    assert index.stat().st_mtime_ns == stamp and len(again.entries) == len(lib.entries)
    data = json.loads(index.read_text())
    assert data["key"] == config.key() and "licenses" in data


def test_missing_library_and_unknown_style_are_named():
    with pytest.raises(LibraryError, match="no index.json; build the library with `g1 library build`"):
        MotionLibrary("/nonexistent/library")
    with pytest.raises(LibraryError, match="unknown rollout styles \\['moonwalk'\\]"):
        build_library("/tmp/unused-lib", LibraryConfig(rollout_styles=("moonwalk",)), force=True, progress=False)


def test_cut_keeps_every_frame():
    from g1_control.motion.clip import MotionClip

    n = 95
    clip = MotionClip.from_joint_trajectory(30.0, np.tile([0, 0, 0.75], (n, 1)), np.tile([1.0, 0, 0, 0], (n, 1)),
                                            np.tile(g1.DEFAULT_Q_RAD, (n, 1)))
    pieces = cut(clip, 1.0)
    assert [p.num_frames for p in pieces] == [30, 30, 35]


def test_dance_clip_is_extracted_from_the_wbt_policy():
    from g1_control.library.dance import STANCE_ANKLE_HEIGHT_M, extract_dance

    clip = extract_dance()
    assert clip.duration_s == pytest.approx(131.4, abs=0.2) and clip.style == "dance"
    lowest = clip.body_pos_w_m[:, [clip.body_index(b) for b in g1.FOOT_BODIES], 2].min(axis=1)
    assert np.percentile(lowest, 25) == pytest.approx(STANCE_ANKLE_HEIGHT_M, abs=0.005)
    assert np.all(clip.joint_pos_rad >= g1.Q_MIN_RAD) and np.all(clip.joint_pos_rad <= g1.Q_MAX_RAD)
    assert np.ptp(clip.joint_pos_rad, axis=0).max() > 1.0  # it dances


def test_dance_extraction_refuses_a_policy_without_a_clip(tmp_path):
    from g1_control.library.dance import extract_dance
    from g1_control.motion.exceptions import MotionFormatError

    with pytest.raises(MotionFormatError, match="no such ONNX file"):
        extract_dance(tmp_path / "missing.onnx")
