import json

import pytest

from g1_control.motion.exceptions import MotionFormatError, UnknownJointError
from g1_control.motion.skeletons import LAFAN1, SKELETONS, detect_skeleton, read_joint_map


def test_known_skeletons_are_consistent_and_detected_in_any_order():
    for skeleton in SKELETONS.values():
        skeleton.validate()
        assert set(skeleton.frame_map.values()) >= {"left_toe", "right_rubber_hand", "left_knee_link"}
    shuffled = tuple(reversed(LAFAN1.joints))
    found = detect_skeleton(shuffled)
    assert found.name == "lafan1" and found.joints == shuffled


def lafan1_joint_map(frame_map: dict[str, str] | None = None) -> dict:
    """The LAFAN1 skeleton as a JSON joint map (a dict), with `frame_map` entries added or changed."""
    spec = {**{k: getattr(LAFAN1, k) for k in LAFAN1.__dataclass_fields__}, "joints": list(LAFAN1.joints)}
    spec["frame_map"] = {**LAFAN1.frame_map, **(frame_map or {})}
    return spec


def test_joint_map_with_unknown_joints_names_them(tmp_path):
    spec = lafan1_joint_map({"LeftPinky": "left_rubber_hand"})
    path = tmp_path / "map.json"
    path.write_text(json.dumps(spec))
    with pytest.raises(UnknownJointError, match=r"map.json: joint map names joints the data does not have: \['LeftPinky'\]"):
        read_joint_map(path)
    spec["frame_map"] = LAFAN1.frame_map
    path.write_text(json.dumps(spec))
    assert read_joint_map(path).frame_map == LAFAN1.frame_map
    del spec["pelvis"]
    path.write_text(json.dumps(spec))
    with pytest.raises(MotionFormatError, match=r"joint map lacks \['pelvis'\]"):
        read_joint_map(path)
