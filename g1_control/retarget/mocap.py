"""Offline retargeting: human world joint positions (HumanMotion) -> a G1 MotionClip.

Per clip: resample to the output rate, scale the human to the G1 by height (and per limb when
configured), label foot contacts from the human feet, put the human's stance feet at the G1's
sole height (an offset measured from the data per foot point, never a fixed constant), then run
the same IKRetargeter as the online loop frame by frame: keypoint position targets, pelvis and
torso orientation from the hips/shoulders, stance feet held, joint position and velocity limits,
feet above the ground.
"""

from __future__ import annotations

import dataclasses
import functools
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pinocchio as pin

from g1_control import rotations as quat
from g1_control.ik.configuration import Configuration, sole_depth_m
from g1_control.ik.exceptions import IKError
from g1_control.ik.retargeter import IKConfig, IKRetargeter
from g1_control.motion.clip import MotionClip
from g1_control.motion.contacts import stance_from_trajectory
from g1_control.motion.exceptions import UnknownJointError
from g1_control.motion.human import HumanMotion
from g1_control.motion.interpolation import interpolate_positions, resample_times
from g1_control.motion.objects import ObjectShape, ObjectTrack
from g1_control.motion.skeletons import Skeleton, detect_skeleton, read_joint_map
from g1_control.robot import description, g1
from g1_control.types import KinematicReference

G1_HEIGHT_M = 1.32
"""Standing height of the G1 (Unitree's specification: 1320 mm)."""
FALLBACK_HUMAN_HEIGHT_M = 1.75
LIMBS = ("left_arm", "right_arm", "left_leg", "right_leg")
HAND_FRAMES = ("left_rubber_hand", "right_rubber_hand")


def load_joint_map(path: str | Path) -> Skeleton:
    """A skeleton from a JSON joint map (g1_control/motion/skeletons.py: read_joint_map) whose G1
    frames all exist in the IK's model. Unknown joints or G1 frames are refused."""
    skeleton = read_joint_map(path)
    conf = Configuration()
    bad = [f for f in skeleton.frame_map.values() if not conf.model.existFrame(f)]
    if bad:
        raise UnknownJointError(f"{path}: joint map targets G1 frames that do not exist: {bad}")
    return skeleton


@dataclass
class MocapRetargetConfig:
    fps: float = 30.0
    """Output frame rate (Hz); the input is resampled to it before IK."""
    robot_height_m: float = G1_HEIGHT_M
    human_height_m: float | None = None
    """Overrides the height the data carries (or the skeleton's default)."""
    limb_scale: dict[str, float] = field(default_factory=dict)
    """Extra factor per limb (left_arm, right_arm, left_leg, right_leg) on top of the height scale,
    applied to the limb's joints relative to its root joint."""
    keypoint_cost: float = 4.0
    end_effector_cost: float = 10.0
    root_position_cost: float = 2.0
    pelvis_orientation_cost: float = 4.0
    torso_orientation_cost: float = 2.0
    foot_orientation_cost: float = 0.5
    posture_cost: float = 0.05
    wrist_posture_cost: float = 0.5
    """Wrists are nearly free under hand position targets; a firmer posture pull stops them
    wandering between equivalent solutions (measured: chatter at the wrist velocity limit)."""
    smoothness_cost: float = 0.2
    iterations: int = 2
    warmup_iterations: int = 30
    stance_speed_mps: float = 0.25
    """A human foot point slower than this (after scaling) is in stance."""
    object_contact_m: float = 0.06
    """A frame is a hand-object contact when the human's hand keypoint (the joint mapped to the
    G1's hand, a wrist) is within this of the object's surface, robot scale (a gripping wrist
    sits 2-5 cm from a box's face)."""
    velocity_limit_scale: float = 1.0
    free_yaw_stance: bool = False
    """Stance feet may pivot about the vertical (IKConfig.contact_free_yaw). Off: on the demo
    climbing clips it raised stance sliding (seq 4: 0.9 % -> 6.3 % of stance frames)."""
    self_collision: bool = True
    """Keep the arms out of the torso and the legs apart (human arms pass closer to the body than
    the G1's wider torso allows)."""

    def validate(self) -> MocapRetargetConfig:
        if not self.fps > 0:
            raise IKError(f"MocapRetargetConfig.fps must be > 0. Got {self.fps}")
        unknown = set(self.limb_scale) - set(LIMBS)
        if unknown:
            raise IKError(f"MocapRetargetConfig.limb_scale has unknown limbs {sorted(unknown)}; known: {LIMBS}")
        if not self.object_contact_m > 0:
            raise IKError(f"MocapRetargetConfig.object_contact_m must be > 0 m. Got {self.object_contact_m}")
        if self.human_height_m is not None and not self.human_height_m > 0:
            raise IKError(f"human height must be > 0 m. Got {self.human_height_m}")
        return self


def _normalize(v: np.ndarray) -> np.ndarray:
    return v / np.maximum(np.linalg.norm(v, axis=-1, keepdims=True), 1e-9)


def frame_from_left_up(left: np.ndarray, up: np.ndarray) -> np.ndarray:
    """(T, 3, 3) rotations with y along `left` and z as close to `up` as possible (x forward)."""
    y = _normalize(left)
    x = _normalize(np.cross(y, up))
    z = np.cross(x, y)
    return np.stack([x, y, z], axis=-1)


def _yaw_frames(forward: np.ndarray) -> np.ndarray:
    f = forward.copy()
    f[:, 2] = 0.0
    yaw = np.arctan2(f[:, 1], f[:, 0])
    c, s = np.cos(yaw), np.sin(yaw)
    rot = np.zeros((len(yaw), 3, 3))
    rot[:, 0, 0], rot[:, 0, 1], rot[:, 1, 0], rot[:, 1, 1], rot[:, 2, 2] = c, -s, s, c, 1.0
    return rot


@dataclass
class PreparedTargets:
    """Per-frame targets at the output rate, robot scale."""

    fps: float
    keypoints_w_m: dict[str, np.ndarray]
    """G1 frame -> (T, 3) target position."""
    root_pos_w_m: np.ndarray
    pelvis_rot: np.ndarray
    torso_rot: np.ndarray
    foot_rot: tuple[np.ndarray, np.ndarray]
    contacts: np.ndarray
    scale: float
    object: ObjectTrack | None = None
    """The handled object at the output rate and robot scale, hand contacts labelled."""
    scene: tuple[ObjectShape, ...] = ()
    """Static shapes around the motion, robot scale."""


def _stance_height(z: np.ndarray, stance: np.ndarray) -> float:
    """Typical height of a foot point while it rests on the lowest support in the clip."""
    low = z < z.min() + 0.05
    pick = stance & low
    return float(np.median(z[pick])) if pick.any() else float(z.min())


def prepare_targets(motion: HumanMotion, skeleton: Skeleton, config: MocapRetargetConfig,
                    robot_sole_heights: dict[str, float]) -> PreparedTargets:
    height = config.human_height_m or motion.height_m or skeleton.default_height_m or FALLBACK_HUMAN_HEIGHT_M
    scale = config.robot_height_m / height
    times = resample_times(motion.num_frames, motion.fps, config.fps)
    pos = interpolate_positions(motion.positions_w_m, motion.fps, times) * scale
    idx = {n: i for i, n in enumerate(motion.joint_names)}
    for limb, chain in skeleton.limb_chains().items():
        factor = config.limb_scale.get(limb, 1.0)
        if factor != 1.0 and chain:
            root = pos[:, idx[chain[0]]].copy()
            for name in chain[1:]:
                pos[:, idx[name]] = root + factor * (pos[:, idx[name]] - root)

    def p(name: str) -> np.ndarray:
        return pos[:, idx[name]]

    contacts = np.zeros((len(times), 2), dtype=bool)
    for side, (ankle, toe) in enumerate(((skeleton.left_ankle, skeleton.left_toe),
                                         (skeleton.right_ankle, skeleton.right_toe))):
        contacts[:, side] = stance_from_trajectory(0.5 * (p(ankle) + p(toe)), config.fps, config.stance_speed_mps,
                                                   min_frames=3)
    keypoints = {}
    foot_points = {skeleton.left_ankle: 0, skeleton.left_toe: 0, skeleton.right_ankle: 1, skeleton.right_toe: 1}
    for human, frame in skeleton.frame_map.items():
        target = p(human).copy()
        if human in foot_points and frame in robot_sole_heights:
            # Put the human's stance height of this foot point at the G1's (data-derived offset).
            side = foot_points[human]
            target[:, 2] += robot_sole_heights[frame] - _stance_height(target[:, 2], contacts[:, side])
        keypoints[frame] = target
    pelvis_rot = frame_from_left_up(p(skeleton.left_hip) - p(skeleton.right_hip), p(skeleton.spine_top) - p(skeleton.pelvis))
    torso_rot = frame_from_left_up(p(skeleton.left_shoulder) - p(skeleton.right_shoulder),
                                   0.5 * (p(skeleton.left_shoulder) + p(skeleton.right_shoulder)) - p(skeleton.pelvis))
    hip_mid = 0.5 * (p(skeleton.left_hip) + p(skeleton.right_hip))
    root = hip_mid + np.einsum("tij,j->ti", pelvis_rot, _pelvis_above_hips())
    foot_rot = (_yaw_frames(p(skeleton.left_toe) - p(skeleton.left_ankle)),
                _yaw_frames(p(skeleton.right_toe) - p(skeleton.right_ankle)))
    track = None
    if motion.object is not None:
        track = motion.object.resampled(motion.fps, times).scaled(scale)
        hands = [next((h for h, f in skeleton.frame_map.items() if f == frame), None) for frame in HAND_FRAMES]
        found = [h for h in hands if h is not None]
        if len(found) == len(hands):
            track.hand_contacts = track.distance(np.stack([p(h) for h in found], axis=1)) < config.object_contact_m
    scene = tuple(shape.scaled(scale) for shape in motion.scene)
    return PreparedTargets(config.fps, keypoints, root, pelvis_rot, torso_rot, foot_rot, contacts, scale, track,
                           scene)


@functools.cache
def _pelvis_above_hips() -> np.ndarray:
    """Pelvis origin relative to the midpoint of the hip pitch links, in the pelvis frame (G1 model)."""
    model = description.pinocchio_model()
    data = model.createData()
    q = description.pinocchio_q(np.zeros(3), np.array([1.0, 0.0, 0.0, 0.0]), np.zeros(g1.NUM_JOINTS))
    pin.framesForwardKinematics(model, data, q)
    hips = [data.oMf[model.getFrameId(n)].translation for n in ("left_hip_pitch_link", "right_hip_pitch_link")]
    return -0.5 * (hips[0] + hips[1])


def _pose7(pos: np.ndarray, rot: np.ndarray) -> np.ndarray:
    q = pin.Quaternion(rot)
    return np.array([pos[0], pos[1], pos[2], q.w, q.x, q.y, q.z])


class MocapRetargeter:
    def __init__(self, config: MocapRetargetConfig | None = None) -> None:
        self.config = (config or MocapRetargetConfig()).validate()

    def ik_config(self, skeleton: Skeleton) -> IKConfig:
        cfg = self.config
        ends = {"left_ankle_roll_link", "right_ankle_roll_link", "left_toe", "right_toe", "left_rubber_hand",
                "right_rubber_hand"}
        costs = {frame: ((cfg.end_effector_cost if frame in ends else cfg.keypoint_cost), 0.0)
                 for frame in skeleton.frame_map.values()}
        for foot in g1.FOOT_BODIES:
            costs[foot] = (costs.get(foot, (cfg.end_effector_cost, 0.0))[0], cfg.foot_orientation_cost)
        costs[g1.TORSO_BODY] = (0.0, cfg.torso_orientation_cost)
        return IKConfig(
            dt_s=1.0 / cfg.fps, iterations=cfg.iterations,
            root_cost=(cfg.root_position_cost, cfg.pelvis_orientation_cost), frame_costs=costs,
            com_cost=(0.0, 0.0, 0.0),
            posture_cost=tuple(cfg.wrist_posture_cost if "wrist" in n else cfg.posture_cost for n in g1.JOINT_NAMES), smoothness_cost=cfg.smoothness_cost,
            velocity_limit_scale=cfg.velocity_limit_scale, self_collision=cfg.self_collision,
            contact_free_yaw=cfg.free_yaw_stance,
        )

    def retarget(self, motion: HumanMotion, skeleton: Skeleton | None = None,
                 progress: Callable[[int], object] | None = None) -> MotionClip:
        motion.validate()
        skeleton = skeleton or detect_skeleton(motion.joint_names, motion.source)
        skeleton = skeleton.validate(motion.source)
        sole = {f: sole_depth_m(f) for f in g1.FOOT_BODIES}
        sole.update({"left_toe": 0.0, "right_toe": 0.0})
        targets = prepare_targets(motion, skeleton, self.config, sole)
        # the scene's box tops are floor too (ground limit, touchdowns)
        ik = IKRetargeter(dataclasses.replace(self.ik_config(skeleton), scene=targets.scene))
        n = targets.root_pos_w_m.shape[0]
        root_quats = quat.from_matrix(targets.pelvis_rot)
        refs = []
        for k in range(n):
            frame_targets = {f: np.concatenate([v[k], [1.0, 0.0, 0.0, 0.0]]) for f, v in targets.keypoints_w_m.items()}
            frame_targets[g1.TORSO_BODY] = _pose7(np.zeros(3), targets.torso_rot[k])
            for side, foot in enumerate(g1.FOOT_BODIES):
                frame_targets[foot] = _pose7(frame_targets[foot][:3], targets.foot_rot[side][k])
            refs.append(KinematicReference(t_s=k / targets.fps, root_pos_w_m=targets.root_pos_w_m[k],
                                           root_quat_wxyz=root_quats[k], q_rad=np.asarray(g1.DEFAULT_Q_RAD).copy(),
                                           frame_targets_w=frame_targets, contacts=targets.contacts[k]))
        # Converge on the first frame with the feet free, then start the clip from there.
        q = description.pinocchio_q(targets.root_pos_w_m[0], root_quats[0], g1.DEFAULT_Q_RAD)
        first_free = KinematicReference(**{**refs[0].__dict__, "contacts": np.zeros(2, dtype=bool)})
        for _ in range(self.config.warmup_iterations):
            q = ik.step(first_free, q)
        ik.reset(q)
        qs = np.empty((n, ik.configuration.nq))
        robot_contacts = np.zeros((n, 2), dtype=bool)
        for k, ref in enumerate(refs):
            q = ik.step(ref, q)
            qs[k] = q
            robot_contacts[k] = [c.active for c in ik.contacts]
            if progress is not None:
                progress(1)
        return MotionClip.from_joint_trajectory(
            targets.fps, qs[:, :3], qs[:, [6, 3, 4, 5]], qs[:, 7:], contacts=robot_contacts, source=motion.source,
            style="default", tags=("retargeted", skeleton.name, f"scale={targets.scale:.4f}"), object=targets.object,
            scene=targets.scene)
