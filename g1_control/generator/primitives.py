"""Smart primitives: operator intent -> a target keyframe (what is given of it, and when).

- Locomotion: the root's future from the velocity/heading command by critically damped springs
  (the "spring character" of game animation that MotionBricks' smart locomotion also uses): the
  planar velocity follows the command exponentially with a half-life, the heading follows either
  the integrated turn rate or an absolute heading with a critically damped second-order spring.
  The keyframe gives the root where the spring puts it at the end of the horizon.
- Style: the style's mean upper-body posture joins the keyframe (waist and arms given).
- Height: a commanded pelvis height is given on the keyframe (else the style's median height).
- Box (smart object): walk to an approach point in front of the box, facing it; then the
  grasp keyframe (crouched pelvis, hands on the box sides) taken from the lift clips; or, for
  "climb", the root on top of the box.
- Effector goals: a hand's target point is given as an effector position on the keyframe
  (COMET-style partial keyframe) and passed on to the IK as a frame target.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field

import numpy as np

from g1_control.robot import g1

LN2 = math.log(2.0)


@dataclass
class SpringConfig:
    velocity_halflife_s: float = 0.25
    heading_halflife_s: float = 0.3
    max_vx_mps: float = 0.8
    max_vy_mps: float = 0.4
    max_wz_radps: float = 1.0


@dataclass
class RootState:
    """Planar root state in the world: position, heading, and their rates."""

    pos_xy: np.ndarray = field(default_factory=lambda: np.zeros(2))
    vel_xy: np.ndarray = field(default_factory=lambda: np.zeros(2))
    yaw: float = 0.0
    yaw_rate: float = 0.0


def spring_root_trajectory(start: RootState, v_cmd_heading: np.ndarray, wz_cmd: float, heading_cmd: float | None,
                           horizon_s: float, dt_s: float, cfg: SpringConfig) -> tuple[np.ndarray, np.ndarray]:
    """Root (x, y) and yaw over the horizon (n, 2), (n,), n = horizon/dt frames after the start.

    Velocity: dv/dt = -lam (v - v_cmd), lam = ln2 / half-life (exact exponential per step).
    Heading with an absolute target: critically damped x(t) = x_d + (j0 + j1 t) e^{-y t}, y = 2 ln2 / half-life.
    """
    n = max(1, round(horizon_s / dt_s))
    decay = math.exp(-LN2 / cfg.velocity_halflife_s * dt_s)
    weights, powers, t = _spring_weights(n, decay, dt_s)
    vx = min(max(float(v_cmd_heading[0]), -cfg.max_vx_mps), cfg.max_vx_mps)
    vy = min(max(float(v_cmd_heading[1]), -cfg.max_vy_mps), cfg.max_vy_mps)
    wz_cmd = min(max(float(wz_cmd), -cfg.max_wz_radps), cfg.max_wz_radps)
    # Closed forms evaluated at every frame (vectorized: this runs on every replan).
    if heading_cmd is None:
        rate = wz_cmd + (start.yaw_rate - wz_cmd) * powers
        yaw = start.yaw + np.cumsum(rate) * dt_s
    else:
        y = 2.0 * LN2 / cfg.heading_halflife_s
        err0 = (start.yaw - heading_cmd + math.pi) % (2 * math.pi) - math.pi
        j1 = start.yaw_rate + err0 * y
        yaw = heading_cmd + (err0 + j1 * t) * np.exp(-y * t)
    c, s = np.cos(yaw), np.sin(yaw)
    target_w = np.empty((n, 2))
    target_w[:, 0] = c * vx - s * vy
    target_w[:, 1] = s * vx + c * vy
    # v_k = d v_{k-1} + (1 - d) target_k  =>  v = d^k v0 + W @ target with W[k, j] = (1 - d) d^(k - j), j <= k
    vel = weights @ target_w
    vel += powers[:, None] * start.vel_xy[None, :]
    pos = start.pos_xy[None, :] + np.cumsum(vel, axis=0) * dt_s
    return pos, yaw


@functools.lru_cache(maxsize=16)
def _spring_weights(n: int, decay: float, dt_s: float) -> tuple[np.ndarray, ...]:
    """The velocity spring's (n, n) lower-triangular weights, decay^k and t = k dt (cached: the
    same for every replan of a horizon)."""
    k = np.arange(1, n + 1)
    lag = k[:, None] - k[None, :]
    weights = np.where(lag >= 0, (1 - decay) * decay ** np.maximum(lag, 0), 0.0)
    powers = decay ** k
    t = k * dt_s
    for a in (weights, powers, t):
        a.setflags(write=False)
    return weights, powers, t


def root_features(pos_xy: np.ndarray, height: float, yaw: float, tilt_rot: np.ndarray | None = None) -> np.ndarray:
    """Root block (9,) of a world-frame feature vector: position and a yaw-only (or given) rotation."""
    out = np.zeros(9)
    out[0:2], out[2] = pos_xy, height
    c, s = math.cos(yaw), math.sin(yaw)
    if tilt_rot is None:
        out[3], out[4], out[7], out[6] = c, s, c, -s
        return out
    rot = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]) @ tilt_rot
    out[3:6], out[6:9] = rot[:, 0], rot[:, 1]
    return out


@dataclass
class Keyframe:
    """A target keyframe in the world frame: values, which of them are given, the gap in frames."""

    values: np.ndarray
    given: np.ndarray
    gap: int
    style: str
    frame_targets_w: dict[str, np.ndarray] = field(default_factory=dict)


def box_approach(box_pos_w: np.ndarray, robot_xy: np.ndarray, standoff_m: float) -> tuple[np.ndarray, float]:
    """Where to stand in front of a box (on the line from the robot to it) and the heading facing it."""
    d = box_pos_w[:2] - robot_xy
    dist = float(np.linalg.norm(d))
    direction = d / dist if dist > 1e-6 else np.array([1.0, 0.0])
    return box_pos_w[:2] - direction * standoff_m, float(math.atan2(direction[1], direction[0]))


def hand_targets_on_box(box_pos_w: np.ndarray, yaw: float, half_width_m: float) -> dict[str, np.ndarray]:
    """Both hands on the box's sides (left hand on the robot's left), at the box centre height."""
    c, s = math.cos(yaw), math.sin(yaw)
    left = np.array([-s, c, 0.0])
    out = {}
    for name, sign in zip(g1.HAND_BODIES, (1.0, -1.0)):
        p = box_pos_w + sign * half_width_m * left
        out[name] = np.concatenate([p, [1.0, 0.0, 0.0, 0.0]])
    return out
