"""A foot that is not held (the performer's foot is off the ground) but is near what it stands on
either lifts clear of it or crosses it slowly, so it never slides over the ground.

A clip checker counts a foot as standing when its lowest collision sphere is within 2 cm of the
floor (or a box top) and slow vertically, and counts it as sliding when that sphere then moves more
than 1 cm across (retarget/clip_geometry.py). Human feet shuffle and skim the floor on their way to
the next step; the G1's foot, following them, would slide. Per tick, for a free foot whose sole
starts within `near_m` of its support (`plan`):
- its target moves across by more than `max_slide_m` this tick: LIFT, every sole sphere ends the
  tick at least `clearance_m` above the support (the step becomes a small step up and over);
- otherwise: SLOW, every sole sphere moves at most `max_slide_m` across over the tick (a box of
  half-width max_slide_m / sqrt(2) per axis, anchored where the tick started).
A foot further from the ground gets no rows: in one tick it can only come down into the 2 cm band
fast (faster than the checker's 0.1 m/s), which is no stance.
"""

from __future__ import annotations

import enum
import math

import numpy as np

from g1_control.ik.configuration import Configuration, foot_contact_points
from g1_control.ik.exceptions import LimitDefinitionError
from g1_control.ik.limits.base import INF, Limit, RowConstraint


class SwingMode(enum.Enum):
    FREE = "free"
    LIFT = "lift"
    SLOW = "slow"


class SwingFootLimit(Limit):
    def __init__(self, frame: str, near_m: float = 0.03, clearance_m: float = 0.025,
                 max_slide_m: float = 0.009) -> None:
        if not (max_slide_m > 0 and 0 < clearance_m <= near_m):
            raise LimitDefinitionError("SwingFootLimit needs max_slide_m > 0 and 0 < clearance_m <= near_m. "
                                       f"Got slide {max_slide_m}, clearance {clearance_m}, near {near_m}")
        spheres = foot_contact_points().get(frame)
        if spheres is None:
            raise LimitDefinitionError(f"SwingFootLimit: '{frame}' has no sole spheres in the URDF")
        self.frame = frame
        self.near_m, self.clearance_m, self.max_slide_m = float(near_m), float(clearance_m), float(max_slide_m)
        self._centres = np.array([c for c, _ in spheres])
        self._radii = np.array([r for _, r in spheres])
        self.mode = SwingMode.FREE
        self._support_m = np.zeros(len(self._radii))
        self._start_xy: np.ndarray | None = None

    def sphere_centres_w(self, configuration: Configuration) -> np.ndarray:
        pose = configuration.frame_placement(configuration.frame_id(self.frame))
        return self._centres @ pose.rotation.T + pose.translation

    def sole_height(self, configuration: Configuration) -> float:
        """Height of the lowest sole sphere's bottom."""
        return float((self.sphere_centres_w(configuration)[:, 2] - self._radii).min())

    def bottoms_w(self, configuration: Configuration) -> np.ndarray:
        """(4, 3) lowest point of each sole sphere."""
        out = self.sphere_centres_w(configuration)
        out[:, 2] -= self._radii
        return out

    def plan(self, configuration: Configuration, supports_m: np.ndarray, target_xy: np.ndarray | None) -> SwingMode:
        """Choose this tick's mode from where the foot starts (the configuration at the tick's start),
        the height of what each sole sphere stands on (4,) (a ramp's top differs from heel to toe) and
        where the foot's target is across (None: no target)."""
        bottoms = self.bottoms_w(configuration)
        self._support_m = np.asarray(supports_m, dtype=float).copy()
        if float((bottoms[:, 2] - self._support_m).min()) >= self.near_m:
            self.mode = SwingMode.FREE
            return self.mode
        origin = configuration.frame_placement(configuration.frame_id(self.frame)).translation
        moving = target_xy is not None and float(np.hypot(*(np.asarray(target_xy) - origin[:2]))) > self.max_slide_m
        self.mode = SwingMode.LIFT if moving else SwingMode.SLOW
        self._start_xy = bottoms[:, :2].copy()
        return self.mode

    def release(self) -> None:
        self.mode = SwingMode.FREE

    def compute(self, configuration: Configuration, dt_s: float) -> RowConstraint | None:
        if self.mode is SwingMode.FREE:
            return None
        fid = configuration.frame_id(self.frame)
        pose = configuration.frame_placement(fid)
        jac = configuration.frame_jacobian(fid)
        arms = self._centres @ pose.rotation.T
        now = arms + pose.translation
        # velocity of a point: v_origin + w x arm
        jx = jac[0] + arms[:, 2:3] * jac[4] - arms[:, 1:2] * jac[5]
        jy = jac[1] + arms[:, 0:1] * jac[5] - arms[:, 2:3] * jac[3]
        jz = jac[2] + arms[:, 1:2] * jac[3] - arms[:, 0:1] * jac[4]
        if self.mode is SwingMode.LIFT:
            lower = self._support_m + self.clearance_m + self._radii - now[:, 2]
            return RowConstraint(jz, lower, np.full(lower.shape, INF))
        half = self.max_slide_m / math.sqrt(2.0)
        moved = now[:, :2] - self._start_xy
        lower = np.concatenate([-half - moved[:, 0], -half - moved[:, 1]])
        upper = np.concatenate([half - moved[:, 0], half - moved[:, 1]])
        return RowConstraint(np.concatenate([jx, jy]), lower, upper)
