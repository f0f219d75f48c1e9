"""Keep body parts from passing through each other: pairs of spheres attached to robot frames
must stay at least `margin_m` apart (surface to surface).

For a pair (a, b) with centres p_a, p_b, radii r_a, r_b and unit normal n = (p_a - p_b) / |p_a - p_b|,
the step must keep  |p_a - p_b| - r_a - r_b + n^T (J_a - J_b) dq >= margin  (first order).
Only pairs closer than `activation_m` enter the QP, so far-apart limbs cost nothing.

The default spheres are coarse G1 proxies measured on the model (torso link chest and belly, pelvis,
elbows, hands, knees, ankles): they stop arms going through the torso and legs crossing, the
failure retargeters without self-collision show; they are not a collision model for contact.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from g1_control.ik.configuration import Configuration
from g1_control.ik.exceptions import LimitDefinitionError
from g1_control.ik.limits.base import INF, Limit, RowConstraint


@dataclass(frozen=True)
class Sphere:
    frame: str
    offset_m: tuple[float, float, float]
    """Centre in the frame's coordinates (m)."""
    radius_m: float


_TORSO = (Sphere("torso_link", (0.0, 0.0, 0.12), 0.10), Sphere("torso_link", (0.0, 0.0, 0.24), 0.09),
          Sphere("pelvis", (0.0, 0.0, -0.02), 0.09))
_ARM = {side: (Sphere(f"{side}_elbow_link", (0.0, 0.0, 0.0), 0.04), Sphere(f"{side}_rubber_hand", (0.0, 0.0, 0.0), 0.04))
        for side in ("left", "right")}
_LEG = {side: (Sphere(f"{side}_knee_link", (0.0, 0.0, 0.0), 0.05), Sphere(f"{side}_ankle_roll_link", (0.0, 0.0, 0.0), 0.05))
        for side in ("left", "right")}

DEFAULT_PAIRS: tuple[tuple[Sphere, Sphere], ...] = tuple(
    [(limb, body) for side in ("left", "right") for limb in _ARM[side] for body in _TORSO]
    + [(a, b) for a in _LEG["left"] for b in _LEG["right"]]
)
"""Arms (elbow, hand) against torso and pelvis; left leg (knee, ankle) against right leg."""


class SelfCollisionLimit(Limit):
    def __init__(self, pairs: tuple[tuple[Sphere, Sphere], ...] = DEFAULT_PAIRS, margin_m: float = 0.01,
                 activation_m: float = 0.10) -> None:
        if margin_m < 0 or activation_m <= margin_m:
            raise LimitDefinitionError("SelfCollisionLimit needs 0 <= margin_m < activation_m. "
                                       f"Got margin {margin_m} m, activation {activation_m} m")
        for a, b in pairs:
            if a.frame == b.frame:
                raise LimitDefinitionError(f"SelfCollisionLimit pair on one frame '{a.frame}' can never move apart")
        self.pairs = pairs
        self.margin_m = float(margin_m)
        self.activation_m = float(activation_m)

    def _centre(self, configuration: Configuration, sphere: Sphere) -> tuple[np.ndarray, np.ndarray, int]:
        fid = configuration.frame_id(sphere.frame)
        placement = configuration.frame_placement(fid)
        arm = placement.rotation @ np.asarray(sphere.offset_m)
        return placement.translation + arm, arm, fid

    def distances(self, configuration: Configuration) -> np.ndarray:
        """Surface-to-surface distance (m) of every pair."""
        out = np.empty(len(self.pairs))
        for i, (a, b) in enumerate(self.pairs):
            pa, _, _ = self._centre(configuration, a)
            pb, _, _ = self._centre(configuration, b)
            out[i] = np.linalg.norm(pa - pb) - a.radius_m - b.radius_m
        return out

    def compute(self, configuration: Configuration, dt_s: float) -> RowConstraint | None:
        rows, lower = [], []
        for a, b in self.pairs:
            pa, arm_a, fa = self._centre(configuration, a)
            pb, arm_b, fb = self._centre(configuration, b)
            delta = pa - pb
            dist = float(np.linalg.norm(delta))
            gap = dist - a.radius_m - b.radius_m
            if gap > self.activation_m or dist < 1e-9:
                continue
            normal = delta / dist
            ja = configuration.frame_jacobian(fa)
            jb = configuration.frame_jacobian(fb)
            # point velocity = v_origin - [arm]x w
            va = ja[:3] - pin.skew(arm_a) @ ja[3:]
            vb = jb[:3] - pin.skew(arm_b) @ jb[3:]
            rows.append(normal @ (va - vb))
            lower.append(self.margin_m - gap)
        if not rows:
            return None
        lower_arr = np.array(lower)
        return RowConstraint(np.array(rows), lower_arr, np.full(len(rows), INF))
