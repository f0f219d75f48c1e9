"""Per-style statistics the runtime needs, taken from the library's training clips and shipped
next to the model (style_stats.json): the style's mean upper-body posture (its target keyframe
pose), its pelvis height range, and, for the object styles, keyframes relative to the object.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from g1_control.robot import g1


@dataclass
class StyleStats:
    name: str
    upper_pose_rad: np.ndarray
    """(29,) mean posture; legs at the default pose, waist/arms the style's mean."""
    pelvis_height_m: tuple[float, float, float]
    """(5th percentile, median, 95th percentile)."""


def compute_style_stats(clips) -> dict:
    by_style: dict[str, list] = {}
    for c in clips:
        by_style.setdefault(c.style, []).append(c)
    out = {}
    for style, cs in sorted(by_style.items()):
        q = np.concatenate([c.joint_pos_rad for c in cs])
        z = np.concatenate([c.root_pos_w_m[:, 2] for c in cs])
        pose = g1.DEFAULT_Q_RAD.copy()
        ub = list(g1.UPPER_BODY_JOINTS)
        pose[ub] = np.median(q[:, ub], axis=0)
        out[style] = {"upper_pose_rad": pose.tolist(),
                      "pelvis_height_m": [float(np.percentile(z, p)) for p in (5, 50, 95)]}
    # lift: the crouched grasp pose, taken where both hands are lowest in the lift clips
    lift = by_style.get("lift", [])
    if lift:
        best = None
        for c in lift:
            hands = [c.body_index(b) for b in g1.HAND_BODIES]
            h = c.body_pos_w_m[:, hands, 2].mean(axis=1) - c.root_pos_w_m[:, 2] * 0
            k = int(np.argmin(h))
            if best is None or h[k] < best[0]:
                best = (h[k], c, k)
        assert best is not None  # lift has at least one clip
        _, c, k = best
        out["lift"]["grasp_pose_rad"] = c.joint_pos_rad[k].tolist()
        out["lift"]["grasp_pelvis_height_m"] = float(c.root_pos_w_m[k, 2])
    return out


def write_style_stats(library_root, path: Path) -> dict:
    from g1_control.motion.library import MotionLibrary

    lib = MotionLibrary(library_root)
    # Originals only: a style's mirror image (a left-hand wave for a right-hand one) would
    # average the pose into something neither side performs.
    stats = compute_style_stats([lib.load(e) for e in lib.select("train") if not e.mirrored])
    Path(path).write_text(json.dumps(stats, indent=1))
    return stats


def load_style_stats(path: Path) -> dict[str, StyleStats]:
    data = json.loads(Path(path).read_text())
    return {k: StyleStats(k, np.array(v["upper_pose_rad"]), tuple(v["pelvis_height_m"])) for k, v in data.items()}
