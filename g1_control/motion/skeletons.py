"""Human skeletons the retargeter knows, and how each maps onto G1 frames.

A `Skeleton` names the data's joints, which of them drive which G1 frame (position targets),
and the joints that define the pelvis, torso and feet. Joint lists are facts about public data:
the holosoma_retargeting demo data (53-joint "mocap" climbing set; 52-joint SMPL-H layout of the
OMOMO / InterMimic .pt files) and the LAFAN1 BVH skeleton. The pairing of human joints with G1
links follows the same anatomical correspondence those projects use (hip joint -> hip pitch link,
knee -> knee link, shoulder -> shoulder roll link, elbow -> elbow link, ankle -> ankle, toe -> toe,
wrist/hand -> hand).
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

from g1_control.motion.exceptions import MotionFormatError, UnknownJointError


@dataclass(frozen=True)
class Skeleton:
    name: str
    joints: tuple[str, ...]
    """All joint names of the data, in the data's column order."""
    frame_map: dict[str, str]
    """human joint -> G1 frame (position target)."""
    pelvis: str
    left_hip: str
    right_hip: str
    spine_top: str
    """A joint above the pelvis on the spine (chest/neck): with the hips it fixes pelvis and torso."""
    left_shoulder: str
    right_shoulder: str
    left_ankle: str
    right_ankle: str
    left_toe: str
    right_toe: str
    default_height_m: float | None = None
    """Performer height when the data does not say (m)."""

    def validate(self, source: str = "skeleton") -> Skeleton:
        known = set(self.joints)
        named = list(self.frame_map) + [self.pelvis, self.left_hip, self.right_hip, self.spine_top, self.left_shoulder,
                                        self.right_shoulder, self.left_ankle, self.right_ankle, self.left_toe,
                                        self.right_toe]
        unknown = [n for n in named if n not in known]
        if unknown:
            raise UnknownJointError(f"{source}: joint map names joints the data does not have: {sorted(set(unknown))}; "
                                    f"data joints: {', '.join(self.joints)}")
        return self

    def limb_chains(self) -> dict[str, tuple[str, ...]]:
        """Mapped joints per limb, root first (for per-limb scaling)."""
        chains: dict[str, list[str]] = {"left_leg": [], "right_leg": [], "left_arm": [], "right_arm": []}
        for human, frame in self.frame_map.items():
            side = "left" if frame.startswith("left_") else "right" if frame.startswith("right_") else None
            if side is None:
                continue
            limb = "arm" if any(k in frame for k in ("shoulder", "elbow", "wrist", "hand")) else "leg"
            chains[f"{side}_{limb}"].append(human)
        return {k: tuple(v) for k, v in chains.items()}


_G1_MAP_LOWER = ("left_hip_pitch_link", "left_knee_link", "left_ankle_roll_link", "left_toe",
                 "right_hip_pitch_link", "right_knee_link", "right_ankle_roll_link", "right_toe")
_G1_MAP_UPPER = ("left_shoulder_roll_link", "left_elbow_link", "left_rubber_hand",
                 "right_shoulder_roll_link", "right_elbow_link", "right_rubber_hand")


def _fingers(side: str, style: str) -> list[str]:
    names = []
    for finger in ("Thumb", "Index", "Middle", "Ring", "Pinky"):
        for k in (1, 2, 3):
            names.append(f"{side}Hand{finger}{k}" if style == "mocap" else f"{side[0]}_{finger}{k}")
    return names


# holosoma demo "mocap" climbing data: 53 joints (order from holosoma_retargeting's data_type config).
HOLOSOMA_MOCAP = Skeleton(
    name="holosoma_mocap",
    joints=tuple(["Hips", "Spine", "Spine1", "Neck", "Head", "LeftShoulder", "LeftArm", "LeftForeArm", "LeftHand"]
                 + _fingers("Left", "mocap")
                 + ["RightShoulder", "RightArm", "RightForeArm", "RightHand"]
                 + _fingers("Right", "mocap")
                 + ["LeftUpLeg", "LeftLeg", "LeftFoot", "LeftToeBase", "RightUpLeg", "RightLeg", "RightFoot",
                    "RightToeBase", "LeftFootMod", "RightFootMod"]),
    frame_map=dict(zip(("LeftUpLeg", "LeftLeg", "LeftFoot", "LeftToeBase", "RightUpLeg", "RightLeg", "RightFoot",
                        "RightToeBase"), _G1_MAP_LOWER))
    | dict(zip(("LeftArm", "LeftForeArm", "LeftHandMiddle3", "RightArm", "RightForeArm", "RightHandMiddle3"),
               _G1_MAP_UPPER)),
    pelvis="Hips", left_hip="LeftUpLeg", right_hip="RightUpLeg", spine_top="Spine1",
    left_shoulder="LeftArm", right_shoulder="RightArm", left_ankle="LeftFoot", right_ankle="RightFoot",
    left_toe="LeftToeBase", right_toe="RightToeBase",
    default_height_m=1.78,  # holosoma's stated performer height for this set
)

# SMPL-H joint layout of the OMOMO / InterMimic .pt files (52 joints).
SMPLH = Skeleton(
    name="smplh",
    joints=tuple(["Pelvis", "L_Hip", "L_Knee", "L_Ankle", "L_Toe", "R_Hip", "R_Knee", "R_Ankle", "R_Toe", "Torso",
                  "Spine", "Chest", "Neck", "Head", "L_Thorax", "L_Shoulder", "L_Elbow", "L_Wrist"]
                 + [f"L_{f}{k}" for f in ("Index", "Middle", "Pinky", "Ring", "Thumb") for k in (1, 2, 3)]
                 + ["R_Thorax", "R_Shoulder", "R_Elbow", "R_Wrist"]
                 + [f"R_{f}{k}" for f in ("Index", "Middle", "Pinky", "Ring", "Thumb") for k in (1, 2, 3)]),
    frame_map=dict(zip(("L_Hip", "L_Knee", "L_Ankle", "L_Toe", "R_Hip", "R_Knee", "R_Ankle", "R_Toe"),
                       _G1_MAP_LOWER))
    | dict(zip(("L_Shoulder", "L_Elbow", "L_Wrist", "R_Shoulder", "R_Elbow", "R_Wrist"), _G1_MAP_UPPER)),
    pelvis="Pelvis", left_hip="L_Hip", right_hip="R_Hip", spine_top="Chest",
    left_shoulder="L_Shoulder", right_shoulder="R_Shoulder", left_ankle="L_Ankle", right_ankle="R_Ankle",
    left_toe="L_Toe", right_toe="R_Toe",
)

# LAFAN1 BVH skeleton (Ubisoft La Forge); 22 joints.
LAFAN1 = Skeleton(
    name="lafan1",
    joints=("Hips", "LeftUpLeg", "LeftLeg", "LeftFoot", "LeftToe", "RightUpLeg", "RightLeg", "RightFoot", "RightToe",
            "Spine", "Spine1", "Spine2", "Neck", "Head", "LeftShoulder", "LeftArm", "LeftForeArm", "LeftHand",
            "RightShoulder", "RightArm", "RightForeArm", "RightHand"),
    frame_map=dict(zip(("LeftUpLeg", "LeftLeg", "LeftFoot", "LeftToe", "RightUpLeg", "RightLeg", "RightFoot",
                        "RightToe"), _G1_MAP_LOWER))
    | dict(zip(("LeftArm", "LeftForeArm", "LeftHand", "RightArm", "RightForeArm", "RightHand"), _G1_MAP_UPPER)),
    pelvis="Hips", left_hip="LeftUpLeg", right_hip="RightUpLeg", spine_top="Spine2",
    left_shoulder="LeftArm", right_shoulder="RightArm", left_ankle="LeftFoot", right_ankle="RightFoot",
    left_toe="LeftToe", right_toe="RightToe",
    default_height_m=1.75,
)

SKELETONS = {s.name: s for s in (HOLOSOMA_MOCAP, SMPLH, LAFAN1)}


def detect_skeleton(joint_names: tuple[str, ...], source: str = "") -> Skeleton:
    """The known skeleton whose joints are all present in joint_names (in any order)."""
    for skeleton in SKELETONS.values():
        if set(skeleton.frame_map) <= set(joint_names) and {skeleton.pelvis, skeleton.spine_top} <= set(joint_names):
            return Skeleton(**{**skeleton.__dict__, "joints": tuple(joint_names)}).validate(source or skeleton.name)
    raise UnknownJointError(f"{source or 'motion'}: joints {list(joint_names)[:8]}... match no known skeleton "
                            f"({', '.join(SKELETONS)}); pass a joint map file (--joint-map)")


def skeleton_for_count(count: int) -> Skeleton | None:
    """Known skeleton with exactly `count` joints (files that store positions but no names)."""
    for skeleton in SKELETONS.values():
        if len(skeleton.joints) == count:
            return skeleton
    return None


def read_joint_map(path: str | Path) -> Skeleton:
    """A skeleton from a JSON joint map: {"joints": [...], "frame_map": {human: g1_frame}, "pelvis": ...,
    "left_hip": ..., ... (every Skeleton field)}. Unknown joints are refused; whether the G1 frames
    exist is checked by the retargeter's loader (g1_control/retarget/mocap.py: load_joint_map)."""
    path = Path(path)
    try:
        raw = json.loads(path.read_text())
    except (OSError, json.JSONDecodeError) as exc:
        raise MotionFormatError(f"{path}: not a readable JSON joint map ({exc})") from None
    fields = [f for f in Skeleton.__dataclass_fields__ if f not in ("name", "default_height_m")]
    missing = [f for f in fields if f not in raw]
    if missing:
        raise MotionFormatError(f"{path}: joint map lacks {missing}")
    skeleton = Skeleton(name=raw.get("name", path.stem), joints=tuple(raw["joints"]), frame_map=dict(raw["frame_map"]),
                        **{f: raw[f] for f in fields if f not in ("joints", "frame_map")},
                        default_height_m=raw.get("default_height_m"))
    return skeleton.validate(str(path))
