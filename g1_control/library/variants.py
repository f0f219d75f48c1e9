"""Motion libraries of the other G1 variants, derived clip by clip from the 29-DoF library
(`g1 library build --variant g1_23dof | g1_29dof_with_hand`).

The 29-DoF library holds the physics rollouts, the dance clip and the retargeted mocap. Each of its
original (unmirrored) clips is carried over to the variant, then mirrored, with the 29-DoF
library's names and splits (so held-out motion stays held out for every variant):

- g1_23dof (mode_machine 4: no waist roll/pitch, no wrist pitch/yaw). Every frame goes through the
  project's IK (ik.IKRetargeter) with those six joints locked at 0: pelvis pose, feet (position
  and orientation, stance feet held, ground and scene boxes), hands, elbows, knees and the torso's
  orientation of the 29-DoF frame are the targets. Where the 29-DoF motion bent the waist (dance,
  lift, climb) the 23-DoF solution leans with the hips instead; the recorded residual (hand and
  foot error against the 29-DoF targets) is written to the index.
- g1_29dof_with_hand (Dex3-1 hands, 14 finger joints). Its 29 body joints have the same placements
  as the 29-DoF URDF (checked in skeleton.py), so the IK would return the same body motion; that
  is kept. The library has no finger recordings: the fingers follow a grasp synergy
  (open -> closed per hand, `grasp_synergy`) driven by what the clip does - the hand-object contact
  labels of the lift clips, hands at a scene box in the climbing clips, and a per-style hand shape
  for the rollouts (a fist for guard, a grip for carry, an open hand for wave / arms out / reach up,
  relaxed otherwise), low-pass filtered (0.12 s). This is synthesized, and labelled so in the index.

Finger angles are stored next to each clip as clips/<name>.fingers.npy (T, 14), skeleton.FINGER_JOINTS
order. Cached like the base library: rebuilt when the 29-DoF library's key or this builder changes.
"""

from __future__ import annotations

import hashlib
import json
import sys
import time
from pathlib import Path

import numpy as np

from g1_control.generator import skeleton as S
from g1_control.generator.data import FINGER_SUFFIX, finger_path, library_dir, library_variant
from g1_control.motion.clip import MotionClip
from g1_control.motion.library import INDEX_NAME, LibraryError, MotionLibrary
from g1_control.robot import g1

VARIANT_BUILD_VERSION = 1
GRASP_TIME_CONSTANT_S = 0.12
STYLE_GRASP = {"default": 0.3, "arm_swing": 0.3, "look_around": 0.3, "dance": 0.35, "carry": 0.85, "guard": 1.0,
               "wave": 0.0, "arms_out": 0.0, "reach_up": 0.1, "lift": 0.2, "climb": 0.2}
"""Grasp amount (0 open .. 1 closed) per style when nothing in the clip says otherwise."""
CONTACT_GRASP = 0.9
HAND_AT_BOX_M = 0.06


__all__ = ["FINGER_SUFFIX", "build_variant_library", "grasp_synergy", "retarget_locked", "variant_library_dir"]


def variant_library_dir(variant: str) -> Path:
    S.skeleton(variant)  # unknown names fail here
    return library_dir(variant)


# ---------------------------------------------------------------------------------------------- 23-DoF
def _locked_ik(clip: MotionClip, dropped: list[int]):
    from g1_control.ik.limits import JointPositionLimit
    from g1_control.ik.retargeter import IKConfig, IKRetargeter

    hands = {b: (8.0, 0.0) for b in g1.HAND_BODIES}
    feet = {b: (10.0, 2.0) for b in g1.FOOT_BODIES}
    mid = {b: (2.0, 0.0) for b in ("left_elbow_link", "right_elbow_link", "left_knee_link", "right_knee_link")}
    config = IKConfig(dt_s=1.0 / clip.fps, iterations=2, root_cost=(10.0, 5.0),
                      frame_costs={**hands, **feet, **mid, g1.TORSO_BODY: (0.0, 2.0)}, com_cost=(0.0, 0.0, 0.0),
                      posture_cost=0.05, smoothness_cost=0.1, self_collision=False, scene=tuple(clip.scene))
    ik = IKRetargeter(config)
    q_min, q_max = g1.Q_MIN_RAD.copy(), g1.Q_MAX_RAD.copy()
    q_min[dropped], q_max[dropped] = -1e-9, 1e-9
    ik.joint_position_limit = JointPositionLimit(q_min, q_max)
    return ik


def retarget_locked(clip: MotionClip, dropped: list[int], warmup: int = 10) -> tuple[MotionClip, dict]:
    """The clip on a G1 whose `dropped` joints are fixed at 0, through the IK; (clip, residuals)."""
    from g1_control.motion.kinematics import default_body_names
    from g1_control.robot import description
    from g1_control.types import KinematicReference

    ik = _locked_ik(clip, dropped)
    names = clip.body_names
    targets = [*g1.HAND_BODIES, *g1.FOOT_BODIES, "left_elbow_link", "right_elbow_link", "left_knee_link",
               "right_knee_link", g1.TORSO_BODY]
    idx = [names.index(b) for b in targets]
    q_post = clip.joint_pos_rad.copy()
    q_post[:, dropped] = 0.0
    n = clip.num_frames
    refs = []
    for k in range(n):
        ft = {b: np.concatenate([clip.body_pos_w_m[k, i], clip.body_quat_wxyz[k, i]]) for b, i in zip(targets, idx)}
        refs.append(KinematicReference(t_s=k / clip.fps, root_pos_w_m=clip.root_pos_w_m[k],
                                       root_quat_wxyz=clip.root_quat_wxyz[k], q_rad=q_post[k], frame_targets_w=ft,
                                       contacts=np.asarray(clip.contacts[k], dtype=bool)))
    q = description.pinocchio_q(clip.root_pos_w_m[0], clip.root_quat_wxyz[0] / np.linalg.norm(clip.root_quat_wxyz[0]),
                                q_post[0])
    free = KinematicReference(**{**refs[0].__dict__, "contacts": np.zeros(2, dtype=bool)})
    for _ in range(warmup):
        q = ik.step(free, q)
    ik.reset(q)
    qs = np.empty((n, q.shape[0]))
    for k, ref in enumerate(refs):
        q = ik.step(ref, q)
        qs[k] = q
    joints = qs[:, 7:].copy()
    joints[:, dropped] = 0.0
    out = MotionClip.from_joint_trajectory(clip.fps, qs[:, :3], qs[:, [6, 3, 4, 5]], joints, contacts=clip.contacts,
                                           source=clip.source, style=clip.style, tags=tuple(clip.tags) + ("ik_23dof",),
                                           body_names=default_body_names(), object=clip.object, scene=tuple(clip.scene))
    hand = [out.body_names.index(b) for b in g1.HAND_BODIES]
    foot = [out.body_names.index(b) for b in g1.FOOT_BODIES]
    # idx[:2] / idx[2:4]: the clip's hand and foot bodies (targets' order)
    err = {"hand_mean_m": float(np.linalg.norm(out.body_pos_w_m[:, hand] - clip.body_pos_w_m[:, idx[:2]], axis=-1).mean()),
           "foot_mean_m": float(np.linalg.norm(out.body_pos_w_m[:, foot] - clip.body_pos_w_m[:, idx[2:4]], axis=-1).mean())}
    return out, err


# ---------------------------------------------------------------------------------------------- hands
def grasp_synergy(amount: np.ndarray) -> np.ndarray:
    """(T, 2) grasp amount per hand (left, right), 0 open .. 1 closed -> (T, 14) finger angles.
    Closed: both finger joints of index and middle bent to 75 % of their range, the thumb opposed
    (thumb_0 0.4 rad, thumb_1 and thumb_2 at 50 % / 70 % of their closing range)."""
    lo, hi = S.finger_limits()
    closed = np.zeros(S.NUM_FINGERS)
    for k, name in enumerate(S.FINGER_JOINTS):
        left = name.startswith("left")
        if "index" in name or "middle" in name:
            closed[k] = 0.75 * (lo[k] if left else hi[k])
        elif "thumb_0" in name:
            closed[k] = 0.4
        elif "thumb_1" in name:
            closed[k] = 0.5 * (hi[k] if left else lo[k])
        else:  # thumb_2
            closed[k] = 0.7 * (hi[k] if left else lo[k])
    side = np.array([0] * 7 + [1] * 7)
    return np.clip(amount[:, side] * closed[None, :], lo, hi)


def _low_pass(x: np.ndarray, fps: float, tau_s: float) -> np.ndarray:
    a = 1.0 - np.exp(-1.0 / (fps * tau_s))
    out = np.empty_like(x)
    acc = x[0].copy()
    for k in range(len(x)):
        acc += a * (x[k] - acc)
        out[k] = acc
    return out


def grasp_amount(clip: MotionClip) -> np.ndarray:
    """(T, 2) grasp per hand for a clip (see module docstring)."""
    amount = np.full((clip.num_frames, 2), STYLE_GRASP.get(clip.style, 0.3))
    hands = np.stack([clip.body_pos_w_m[:, clip.body_names.index(b)] for b in g1.HAND_BODIES], axis=1)
    if clip.object is not None and clip.object.hand_contacts.any():
        amount = np.where(clip.object.hand_contacts, CONTACT_GRASP, amount)
    for shape in clip.scene:
        d, _ = shape.nearest_face(hands.reshape(-1, 3))
        amount = np.where(d.reshape(-1, 2) < HAND_AT_BOX_M, CONTACT_GRASP, amount)
    return _low_pass(amount, clip.fps, GRASP_TIME_CONSTANT_S)


def mirror_fingers(fingers: np.ndarray) -> np.ndarray:
    perm, sign = S.finger_mirror()
    return fingers[:, perm] * sign


# ---------------------------------------------------------------------------------------------- build
def _key(variant: str, base_key: str) -> str:
    blob = json.dumps({"v": VARIANT_BUILD_VERSION, "variant": variant, "base": base_key}, sort_keys=True)
    return hashlib.sha256(blob.encode()).hexdigest()[:16]


def build_variant_library(variant: str, base_dir: str | Path | None = None, out_dir: str | Path | None = None,
                          *, force: bool = False, progress: bool = True) -> MotionLibrary:
    from tqdm import tqdm

    from g1_control.motion.formats.clip_npz import write_clip_npz
    from g1_control.motion.library import default_library_dir
    from g1_control.motion.mirror import mirror

    if variant == "g1_29dof":
        return MotionLibrary(base_dir or default_library_dir())
    S.skeleton(variant)
    base = MotionLibrary(base_dir or default_library_dir())
    if library_variant(base) != "g1_29dof":
        raise LibraryError(f"{base.root}: variant libraries are derived from a 29-DoF library, not {library_variant(base)}")
    out = Path(out_dir) if out_dir else variant_library_dir(variant)
    key = _key(variant, str(base.index.get("key")))
    index_path = out / INDEX_NAME
    if index_path.is_file() and not force:
        try:
            if json.loads(index_path.read_text()).get("key") == key:
                return MotionLibrary(out)
        except json.JSONDecodeError:
            pass
    started = time.perf_counter()
    (out / "clips").mkdir(parents=True, exist_ok=True)
    for old in (out / "clips").iterdir():
        old.unlink()
    dropped = [i for i in range(g1.NUM_JOINTS) if i not in g1.G1_23DOF.active_joints]
    originals = [e for e in base.entries if not e.mirrored]
    mirrored = {e.name.removesuffix("_mirror"): e for e in base.entries if e.mirrored}
    entries, residuals = [], []
    for e in tqdm(originals, desc=f"library {variant}", unit="clip", file=sys.stderr, disable=not progress):
        clip = base.load(e)
        fingers = None
        if variant == "g1_23dof":
            clip, err = retarget_locked(clip, dropped)
            residuals.append({"clip": e.name, **err})
        else:
            fingers = grasp_synergy(grasp_amount(clip))
        pairs = [(e, clip, fingers)]
        if e.name in mirrored:
            pairs.append((mirrored[e.name], mirror(clip), None if fingers is None else mirror_fingers(fingers)))
        for entry, c, f in pairs:
            c.source = entry.name
            write_clip_npz(c, out / entry.file)
            if f is not None:
                np.save(finger_path(out, entry.file), f.astype(np.float32))
            entries.append({**entry.__dict__, "num_frames": c.num_frames})
    index = {"key": key, "version": VARIANT_BUILD_VERSION, "variant": variant, "fps": base.fps,
             "base": {"root": str(base.root), "key": base.index.get("key")},
             "method": ("29-DoF clips through the IK with waist roll/pitch and wrist pitch/yaw locked at 0"
                        if variant == "g1_23dof" else
                        "29-DoF body motion (identical joint placements); fingers synthesized by a grasp synergy"),
             "licenses": base.index.get("licenses", {}), "build_s": round(time.perf_counter() - started, 1),
             "ik_residuals": residuals, "clips": entries}
    index_path.write_text(json.dumps(index, indent=1))
    return MotionLibrary(out)
