"""`MotionClip`: the G1 motion library's unit, a whole-body trajectory at a fixed frame rate.

Produced by the retargeter (`g1 retarget`) and the format readers, consumed by the motion
generator and the trackers. All arrays are float64 numpy arrays, frame-major (T first); the
world frame is z-up with the ground at z = 0; quaternions are (w, x, y, z).

Fields (T frames, J = 29 joints in `joint_names` order, B bodies in `body_names` order):
    fps                     frames per second (Hz)
    joint_names             (J,) joint names, g1.JOINT_NAMES for every clip this project writes
    body_names              (B,) body (link) names of the FK-derived body arrays
    root_pos_w_m            (T, 3) pelvis position, world, m
    root_quat_wxyz          (T, 4) pelvis orientation, world
    joint_pos_rad           (T, J) joint angles, rad
    joint_vel_radps         (T, J) joint velocities, rad/s (central differences of joint_pos_rad)
    body_pos_w_m            (T, B, 3) body origins, world, m (forward kinematics)
    body_quat_wxyz          (T, B, 4) body orientations, world
    body_lin_vel_w_mps      (T, B, 3) body origin velocities, world, m/s
    body_ang_vel_w_radps    (T, B, 3) body angular velocities, world, rad/s
    contacts                (T, 2) bool, (left foot, right foot) in stance
    source                  where it came from (file name, dataset)
    style                   style label for the generator ("default", "climb", ...)
    tags                    free labels
    object                  the object the motion handles (motion/objects.py ObjectTrack: shape, pose per
                            frame, source hand-contact labels), or None
    scene                   static shapes around the motion (ObjectShape, world coordinates: climbing
                            boxes); the metrics count foot penetration into them
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields

import numpy as np

from g1_control import rotations as quat
from g1_control.motion.exceptions import InvalidClipError
from g1_control.motion.objects import ObjectShape, ObjectTrack
from g1_control.robot import g1

ARRAY_FIELDS = ("root_pos_w_m", "root_quat_wxyz", "joint_pos_rad", "joint_vel_radps", "body_pos_w_m",
                "body_quat_wxyz", "body_lin_vel_w_mps", "body_ang_vel_w_radps", "contacts")


JOINT_LIMIT_SLACK_RAD = 0.5
"""A clip's joint may sit this far outside the G1's limit (retargeting and mocap overshoot); further is
not an angle of this joint (degrees, radians of another joint order, corrupt data)."""


@dataclass
class MotionClip:
    fps: float
    joint_names: tuple[str, ...]
    body_names: tuple[str, ...]
    root_pos_w_m: np.ndarray
    root_quat_wxyz: np.ndarray
    joint_pos_rad: np.ndarray
    joint_vel_radps: np.ndarray
    body_pos_w_m: np.ndarray
    body_quat_wxyz: np.ndarray
    body_lin_vel_w_mps: np.ndarray
    body_ang_vel_w_radps: np.ndarray
    contacts: np.ndarray
    source: str = ""
    style: str = "default"
    tags: tuple[str, ...] = field(default_factory=tuple)
    object: ObjectTrack | None = None
    scene: tuple[ObjectShape, ...] = ()

    # ------------------------------------------------------------------ construction
    @classmethod
    def from_joint_trajectory(cls, fps: float, root_pos_w_m: np.ndarray, root_quat_wxyz: np.ndarray,
                              joint_pos_rad: np.ndarray, contacts: np.ndarray | None = None, source: str = "",
                              style: str = "default", tags: tuple[str, ...] = (),
                              body_names: tuple[str, ...] | None = None,
                              object: ObjectTrack | None = None,
                              scene: tuple[ObjectShape, ...] = ()) -> MotionClip:
        """Build a full clip from root pose + joint angles: velocities by differences, body poses by
        forward kinematics, contacts from foot motion when not given."""
        from g1_control.motion.contacts import foot_contacts
        from g1_control.motion.kinematics import default_body_names, forward_kinematics

        root_pos = np.asarray(root_pos_w_m, dtype=float)
        # Stored as given (a file's values round-trip exactly); FK uses the normalised rotation.
        root_quat = np.asarray(root_quat_wxyz, dtype=float)
        joints = np.asarray(joint_pos_rad, dtype=float)
        if joints.ndim != 2 or joints.shape[0] == 0:
            where = f" '{source}'" if source else ""
            raise InvalidClipError(f"clip{where} has zero frames; a clip needs at least one"
                                   if joints.ndim == 2 else f"clip{where}: joint_pos_rad has shape {joints.shape}; "
                                   "expected (T, 29)")
        _check_frames("joint_pos_rad", joints, source)
        names = body_names or default_body_names()
        body_pos, body_quat = forward_kinematics(root_pos, quat.normalize(root_quat), joints, names)
        if contacts is None:
            feet = [names.index(b) for b in g1.FOOT_BODIES]
            contacts = foot_contacts(body_pos[:, feet], fps)
        clip = cls(
            fps=float(fps), joint_names=g1.JOINT_NAMES, body_names=tuple(names),
            root_pos_w_m=root_pos, root_quat_wxyz=root_quat, joint_pos_rad=joints,
            joint_vel_radps=differentiate(joints, fps),
            body_pos_w_m=body_pos, body_quat_wxyz=body_quat,
            body_lin_vel_w_mps=differentiate(body_pos, fps),
            body_ang_vel_w_radps=quat.angular_velocity_w(body_quat, fps),
            contacts=np.asarray(contacts, dtype=bool), source=source, style=style, tags=tuple(tags), object=object,
            scene=tuple(scene),
        )
        return clip.validate()

    # ------------------------------------------------------------------ checks
    def validate(self) -> MotionClip:
        """Raise InvalidClipError naming the field (and frame) that is wrong; return self."""
        where = f" in '{self.source}'" if self.source else ""
        if not (np.isfinite(self.fps) and self.fps > 0):
            raise InvalidClipError(f"clip{where}: fps is {self.fps}; expected a positive number")
        t = np.asarray(self.root_pos_w_m).shape[0] if np.ndim(self.root_pos_w_m) else 0
        if t == 0:
            raise InvalidClipError(f"clip{where} has zero frames; a clip needs at least one")
        j, b = len(self.joint_names), len(self.body_names)
        expected = {
            "root_pos_w_m": (t, 3), "root_quat_wxyz": (t, 4), "joint_pos_rad": (t, j), "joint_vel_radps": (t, j),
            "body_pos_w_m": (t, b, 3), "body_quat_wxyz": (t, b, 4), "body_lin_vel_w_mps": (t, b, 3),
            "body_ang_vel_w_radps": (t, b, 3), "contacts": (t, 2),
        }
        for name, shape in expected.items():
            arr = np.asarray(getattr(self, name))
            if arr.shape != shape:
                raise InvalidClipError(f"clip{where}: {name} has shape {arr.shape}; expected {shape}")
            if name != "contacts":
                _check_frames(name, arr, self.source)
        if self.object is not None:
            self.object.validate(t, f"clip{where}")
        unknown = [n for n in self.joint_names if n not in g1.JOINT_INDEX]
        if unknown:
            raise InvalidClipError(f"clip{where}: joint_names has joints the G1 does not have: {unknown[:3]}")
        idx = [g1.JOINT_INDEX[n] for n in self.joint_names]
        lo, hi = g1.Q_MIN_RAD[idx] - JOINT_LIMIT_SLACK_RAD, g1.Q_MAX_RAD[idx] + JOINT_LIMIT_SLACK_RAD
        q = np.asarray(self.joint_pos_rad)
        outside = (q < lo) | (q > hi)
        if outside.any():
            f, k = (int(v[0]) for v in np.nonzero(outside))
            raise InvalidClipError(f"clip{where}: joint_pos_rad[{f}] puts {self.joint_names[k]} at {q[f, k]:+.3f} rad, "
                                   f"more than {JOINT_LIMIT_SLACK_RAD} rad outside its limits: not a G1 angle "
                                   "(degrees? another joint order?)")
        norms = np.linalg.norm(self.root_quat_wxyz, axis=-1)
        bad = np.flatnonzero(np.abs(norms - 1.0) > 1e-3)
        if bad.size:
            raise InvalidClipError(f"clip{where}: root_quat_wxyz at frame {bad[0]} has norm {norms[bad[0]]:.4f}; "
                                   "expected unit quaternions")
        return self

    # ------------------------------------------------------------------ properties
    @property
    def num_frames(self) -> int:
        return int(self.root_pos_w_m.shape[0])

    @property
    def dt_s(self) -> float:
        return 1.0 / self.fps

    @property
    def duration_s(self) -> float:
        return (self.num_frames - 1) / self.fps

    def body_index(self, name: str) -> int:
        try:
            return self.body_names.index(name)
        except ValueError:
            raise InvalidClipError(f"clip has no body '{name}'; bodies: {', '.join(self.body_names)}") from None

    def copy(self) -> MotionClip:
        kwargs = {f.name: getattr(self, f.name) for f in fields(self)}
        for name in ARRAY_FIELDS:
            kwargs[name] = np.array(kwargs[name], copy=True)
        if self.object is not None:
            kwargs["object"] = self.object.take(slice(None))
        return MotionClip(**kwargs)

    def equals(self, other: MotionClip, atol: float = 0.0) -> bool:
        """Same names, fps, tags and arrays (exactly, or within atol)."""
        if (self.fps, self.joint_names, self.body_names, self.source, self.style, tuple(self.tags)) != (
                other.fps, other.joint_names, other.body_names, other.source, other.style, tuple(other.tags)):
            return False
        if len(self.scene) != len(other.scene) or not all(a.equals(b) for a, b in zip(self.scene, other.scene)):
            return False
        if (self.object is None) != (other.object is None) or (
                self.object is not None and not self.object.equals(other.object)):
            return False
        for name in ARRAY_FIELDS:
            a, b = np.asarray(getattr(self, name)), np.asarray(getattr(other, name))
            if a.shape != b.shape:
                return False
            if atol == 0.0 or a.dtype == bool:
                if not np.array_equal(a, b):
                    return False
            elif not np.allclose(a, b, atol=atol, rtol=0.0):
                return False
        return True


def differentiate(x: np.ndarray, fps: float) -> np.ndarray:
    """d/dt along frames: central differences inside, one-sided at the ends (zeros for one frame)."""
    if x.shape[0] < 2:
        return np.zeros_like(x, dtype=float)
    return np.gradient(x, 1.0 / fps, axis=0)


def _check_frames(name: str, arr: np.ndarray, source: str) -> None:
    finite = np.isfinite(arr).reshape(arr.shape[0], -1).all(axis=1) if arr.ndim > 1 else np.isfinite(arr)
    if not finite.all():
        frame = int(np.flatnonzero(~finite)[0])
        where = f" in '{source}'" if source else ""
        raise InvalidClipError(f"clip{where}: {name} has NaN or inf at frame {frame}")
