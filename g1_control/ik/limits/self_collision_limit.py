"""Keep body parts from passing through each other: pairs of spheres attached to robot frames
must stay at least `margin_m` apart (surface to surface).

For a pair (a, b) with centres p_a, p_b, radii r_a, r_b and unit normal n = (p_a - p_b) / |p_a - p_b|,
the step must keep  |p_a - p_b| - r_a - r_b + n^T (J_a - J_b) dq >= margin  (first order).
Only pairs closer than `activation_m` enter the QP, so far-apart limbs cost nothing; a pair that a
large step carries from beyond that distance into the margin is caught after the step
(`missed_pairs`) and the step solved again with it (IKRetargeter).

The default spheres are coarse G1 proxies measured on the model (torso link chest and belly, pelvis,
elbows, hands, knees, ankles): they stop arms going through the torso and legs crossing, the
failure retargeters without self-collision show; they are not a collision model for contact.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

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
        # All pairs are evaluated at once (one placement lookup per frame, array arithmetic per
        # pair): a Python loop over the pairs took about half of the offline retargeting time (profiled).
        # Spheres 0..P-1 are the pairs' first members, P..2P-1 their second ones.
        spheres = [a for a, _ in pairs] + [b for _, b in pairs]
        self._frames = tuple(dict.fromkeys(s.frame for s in spheres))
        self._sphere_frame = np.array([self._frames.index(s.frame) for s in spheres], dtype=np.int64)
        self._offsets = np.array([s.offset_m for s in spheres], dtype=float).reshape(-1, 3)
        self._pair_a = np.arange(len(pairs))
        self._pair_b = np.arange(len(pairs), 2 * len(pairs))
        self._radii = np.array([a.radius_m + b.radius_m for a, b in pairs], dtype=float)
        self.include = np.zeros(len(pairs), dtype=bool)
        """Pairs given rows whatever their distance (see `missed_pairs`); the caller sets and clears it."""
        self._rows = np.zeros(len(pairs), dtype=bool)
        """Pairs the last `compute` gave rows."""

    def _frame_ids(self, configuration: Configuration) -> list[int]:
        return [configuration.frame_id(f) for f in self._frames]

    def _geometry(self, configuration: Configuration) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(centre offsets in world axes (S, 3), pair centre differences p_a - p_b (P, 3), pair
        centre distances (P,)) at the configuration."""
        placements = configuration.placements(self._frame_ids(configuration))[self._sphere_frame]
        offsets_w = np.einsum("sij,sj->si", placements[:, :3, :3], self._offsets)
        centres = placements[:, :3, 3] + offsets_w
        delta = centres[self._pair_a] - centres[self._pair_b]
        return offsets_w, delta, np.sqrt(np.einsum("pi,pi->p", delta, delta))

    def distances(self, configuration: Configuration) -> np.ndarray:
        """Surface-to-surface distance (m) of every pair."""
        if not self.pairs:
            return np.zeros(0)
        return self._geometry(configuration)[2] - self._radii

    def missed_pairs(self, configuration: Configuration) -> np.ndarray:
        """(P,) bool: pairs inside the margin at `configuration` that the last `compute` gave no row.

        A pair enters the QP only within `activation_m` of contact, yet one step may move a sphere
        much further: the joint velocity limits allow v_max * dt per tick (1.2 rad at the shoulder
        and elbow at 30 Hz; measured: an elbow sphere 11-12 cm in one step on climbing mocap). A pair
        just beyond the activation distance when the step is solved can thus end the step inside
        the torso, with no row in the QP to stop it. The caller solves the step again with these
        pairs in `include`."""
        if not self.pairs:
            return np.zeros(0, dtype=bool)
        return (self.distances(configuration) < self.margin_m) & ~self._rows

    def compute(self, configuration: Configuration, dt_s: float) -> RowConstraint | None:
        self._rows[:] = False
        if not self.pairs:
            return None
        offsets_w, delta, dist = self._geometry(configuration)
        gap = dist - self._radii
        self._rows[:] = ((gap <= self.activation_m) | self.include) & (dist >= 1e-9)
        active = np.flatnonzero(self._rows)
        if not active.size:
            return None
        # Frame Jacobians (6, nv) of the frames the active pairs use, fetched once each.
        fids = self._frame_ids(configuration)
        sa, sb = self._pair_a[active], self._pair_b[active]
        fa, fb = self._sphere_frame[sa], self._sphere_frame[sb]
        jacobians = np.empty((len(self._frames), 6, configuration.nv))
        for k in set(fa.tolist() + fb.tolist()):
            jacobians[k] = configuration.frame_jacobian(fids[k])
        normal = delta[active] / dist[active, None]
        # d gap = n^T (v_a - v_b), point velocity v = v_origin + w x offset, so
        # n^T v = n^T J_lin dq + (offset x n)^T J_ang dq (offset: centre - frame origin, world axes).
        weights_a = np.concatenate([normal, _cross(offsets_w[sa], normal)], axis=1)
        weights_b = np.concatenate([normal, _cross(offsets_w[sb], normal)], axis=1)
        rows = (weights_a[:, None, :] @ jacobians[fa] - weights_b[:, None, :] @ jacobians[fb])[:, 0]
        return RowConstraint(rows, self.margin_m - gap[active], np.full(active.size, INF))


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Row-wise a x b for (n, 3) arrays (np.cross costs ~20 us at this size, this ~3 us)."""
    a0, a1, a2 = a.T
    b0, b1, b2 = b.T
    return np.stack([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0], axis=1)
