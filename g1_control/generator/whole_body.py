"""Whole-body references for the whole-body controller: sampled trajectories and the way they
are built from configurations.

WholeBodyTrajectory: root pose, joint angles, the contact schedule and (optionally) the known hand
forces of a held object, sampled in time and played back through cubic splines (joint and root
velocities smooth and exact). Every sample is a PHASE_WHOLE_BODY reference, feasible by
construction: its poses come from the whole-body IK (g1_control/ik/whole_body.py:WholeBodyIK).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.interpolate import CubicSpline

from g1_control.errors import WbcConfigError
from g1_control.robot import g1
from g1_control.rotations import quat_to_rot, rot_to_rpy, rpy_to_quat
from g1_control.types import PHASE_WHOLE_BODY, JointReference


def smoothstep(x: np.ndarray | float) -> np.ndarray:
    """Quintic 0 -> 1 with zero velocity and acceleration at both ends."""
    x = np.clip(x, 0.0, 1.0)
    return x**3 * (10 - 15 * x + 6 * x * x)


@dataclass
class WholeBodyTrajectory:
    """Samples of a whole-body reference; sample(t) interpolates with cubic splines."""

    name: str
    t_s: np.ndarray
    root_pos_w_m: np.ndarray
    root_rpy_rad: np.ndarray
    q_rad: np.ndarray
    contacts: np.ndarray
    """(n, 2) bool per sample; held constant from one sample to the next."""
    extras: dict = field(default_factory=dict)
    hand_forces_w_n: np.ndarray | None = None
    """(n, 2, 3) known forces on the (left, right) hand (JointReference.hand_forces_w_n), linear
    between samples; None: no hand forces."""

    def __post_init__(self) -> None:
        n = len(self.t_s)
        shapes = {"root_pos_w_m": (n, 3), "root_rpy_rad": (n, 3), "q_rad": (n, g1.NUM_JOINTS), "contacts": (n, 2)}
        for name, shape in shapes.items():
            if getattr(self, name).shape != shape:
                raise WbcConfigError(f"WholeBodyTrajectory.{name} has shape {getattr(self, name).shape}; expected {shape}")
        if self.hand_forces_w_n is not None and self.hand_forces_w_n.shape != (n, 2, 3):
            raise WbcConfigError(f"WholeBodyTrajectory.hand_forces_w_n has shape {self.hand_forces_w_n.shape}; "
                                 f"expected {(n, 2, 3)}")
        if n < 2 or np.any(np.diff(self.t_s) <= 0):
            raise WbcConfigError("WholeBodyTrajectory needs at least 2 samples at increasing times")
        if not np.all(self.contacts.any(axis=1)):
            raise WbcConfigError("WholeBodyTrajectory has samples with no foot in contact")
        # One spline over all 35 columns (root xyz, root rpy, joints): two evaluations per sample.
        self._spline = CubicSpline(self.t_s, np.hstack([self.root_pos_w_m, self.root_rpy_rad, self.q_rad]),
                                   bc_type="clamped")
        self._last: tuple[float, JointReference] | None = None

    @property
    def duration_s(self) -> float:
        return float(self.t_s[-1])

    def sample(self, t_s: float, out: JointReference | None = None) -> JointReference:
        out = out or JointReference()
        if self._last is not None and self._last[0] == t_s:  # the same tick asked again
            copy_reference(self._last[1], out)
            return out
        t = float(np.clip(t_s, self.t_s[0], self.t_s[-1]))
        x, dx = self._spline(t), self._spline(t, 1)
        out.t_s = t_s
        out.q_rad[:] = x[6:]
        out.dq_radps[:] = dx[6:]
        out.root_pos_w_m[:] = x[:3]
        rpy, drpy = x[3:6], dx[3:6]
        out.root_quat_wxyz[:] = rpy_to_quat(rpy)
        vel_w = dx[:3]
        c, s = np.cos(rpy[2]), np.sin(rpy[2])
        out.root_linvel_h_mps[:] = (c * vel_w[0] + s * vel_w[1], -s * vel_w[0] + c * vel_w[1], vel_w[2])
        # ZYX Euler rates -> world angular velocity -> heading frame
        _, p, y = rpy
        w_world = np.array([-np.sin(y) * drpy[1] + np.cos(y) * np.cos(p) * drpy[0],
                            np.cos(y) * drpy[1] + np.sin(y) * np.cos(p) * drpy[0],
                            drpy[2] - np.sin(p) * drpy[0]])
        out.root_angvel_h_radps[:] = (c * w_world[0] + s * w_world[1], -s * w_world[0] + c * w_world[1], w_world[2])
        k = min(max(int(np.searchsorted(self.t_s, t, side="right")) - 1, 0), len(self.t_s) - 1)
        out.contacts[:] = self.contacts[k]
        out.phase = PHASE_WHOLE_BODY
        out.upper_body_override = True
        out.pelvis_height_m = None
        if self.hand_forces_w_n is None:
            out.hand_forces_w_n[:] = 0.0
        else:
            k1 = min(k + 1, len(self.t_s) - 1)
            w = 0.0 if k1 == k else (t - self.t_s[k]) / (self.t_s[k1] - self.t_s[k])
            out.hand_forces_w_n[:] = (1 - w) * self.hand_forces_w_n[k] + w * self.hand_forces_w_n[k1]
        if self._last is None:
            self._last = (t_s, JointReference())
        self._last = (t_s, self._last[1])
        copy_reference(out, self._last[1])
        return out


def copy_reference(src: JointReference, dst: JointReference) -> None:
    dst.copy_from(src)


def trajectory_from_configurations(name: str, t: np.ndarray, qs: np.ndarray, contacts: np.ndarray,
                                   hand_forces_w_n: np.ndarray | None = None, **extras) -> WholeBodyTrajectory:
    """From pinocchio configurations (n, 36: xyz, quaternion xyzw, joints) to a trajectory."""
    rpy = np.zeros((len(t), 3))
    for k, qk in enumerate(qs):
        x, y, z, w = qk[3:7]
        rpy[k] = rot_to_rpy(quat_to_rot(np.array([w, x, y, z])))
    rpy[:, 2] = np.unwrap(rpy[:, 2])
    return WholeBodyTrajectory(name, np.asarray(t, dtype=float), qs[:, :3].copy(), rpy, qs[:, 7:].copy(),
                               np.asarray(contacts, dtype=bool), dict(extras), hand_forces_w_n)


def keyframe_trajectory(name: str, keyframes: list[tuple[float, np.ndarray]], *, dt_s: float = 0.02,
                        contacts: np.ndarray | None = None, hand_forces=None, **extras) -> WholeBodyTrajectory:
    """Quintic blends in configuration space between keyframes (time, pinocchio q); a hold is the
    same configuration at a later time. contacts: (2,) both samples' schedule (default both feet);
    hand_forces(t) -> (2, 3): the known hand forces at time t."""
    times = np.array([k[0] for k in keyframes], dtype=float)
    qs = np.array([k[1] for k in keyframes])
    if np.any(np.diff(times) <= 0):
        raise WbcConfigError(f"keyframe_trajectory '{name}': keyframe times must increase; got {times.tolist()}")
    t = np.arange(0.0, times[-1] + 1e-9, dt_s)
    if t[-1] < times[-1] - 1e-9:
        t = np.append(t, times[-1])
    out = np.zeros((len(t), qs.shape[1]))
    j = np.clip(np.searchsorted(times, t, side="right") - 1, 0, len(times) - 2)
    s = smoothstep((t - times[j]) / (times[j + 1] - times[j]))
    out[:] = qs[j] + s[:, None] * (qs[j + 1] - qs[j])
    out[:, 3:7] /= np.linalg.norm(out[:, 3:7], axis=1, keepdims=True)
    c = np.ones((len(t), 2), dtype=bool) if contacts is None else np.broadcast_to(contacts, (len(t), 2)).copy()
    forces = None if hand_forces is None else np.array([hand_forces(tk) for tk in t])
    return trajectory_from_configurations(name, t, out, c, forces, **extras)


__all__ = ["WholeBodyTrajectory", "copy_reference", "keyframe_trajectory", "smoothstep",
           "trajectory_from_configurations"]
