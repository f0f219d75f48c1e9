"""Contact wrench constraints of a flat rectangular foot.

The wrench (fx, fy, fz, tx, ty, tz) acts at the sole frame's origin, in the sole's own axes
(z normal to the ground). For forces spread over the sole plane, tx = py * fz and
ty = -px * fz, so the centre of pressure (px, py) = (-ty / fz, tx / fz). Every constraint below is
linear in the wrench because each bound is scaled by fz:
  friction pyramid   |fx| <= mu fz,  |fy| <= mu fz     (mu: the friction the controller assumes)
  centre of pressure x_min fz <= -ty <= x_max fz,  y_min fz <= tx <= y_max fz
  yaw torque         |tz| <= mu r fz                  (r: a conservative torsion radius)
  normal force       fz_min <= fz <= fz_max
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from g1_control.errors import WbcConfigError

ROWS_PER_FOOT = 11

DEFAULT_FRICTION = 0.7
"""The foot-floor friction coefficient the controller assumes unless the launch file says
(tracker.foot_friction). The pyramid's rows bound each horizontal axis by mu fz, so a diagonal force
may reach sqrt(2) mu fz (walking 0.6 m/s at 0.7 the QP planned |f_t| / f_z up to 0.99, measured).
A lower default (0.45) was measured and not shipped: on `g1 bench robust`'s draws 0-19 it fell on 5
of 20 (0.7: 8), but most of those falls are the command latency's (draws 0, 1, 9 with latency 0
walked; draws 0, 1 with floor friction 1.0 still fell), and on the nominal robot it fell at
forward 1.0 m/s (0.7: 0.844 m/s), walked sideways 0.4 m/s at 0.270 (0.7: 0.401), survived 1 of 20
pushes (0.7: 2) and fell in tests/trackers/wbc/test_wbc_sim.py's 0.3 m/s walk; it did walk 9 of 10
random timelines (0.7: 6). `g1 bench locomotion --only wbc/...`, one run each, same machine.
Measured again at stop 44 (`g1 bench robust --only wbc --seed S --draws N`, 20 s at 0.6 m/s; wbc23
is the 23-DoF G1), falls on draws 20-49: 0.7: wbc 9, wbc23 12; 0.6: 7, 6; 0.5: 4, 7; nominal walking
within 1.6 % at each, the push grid 9/20 at 0.7 and 11/20 at 0.6 and 0.5. Not shipped: at 0.5 the
scripted 0.3 m/s plan walk (test_wbc_sim.py) and a 0.15 m step (test_wbc_steps.py, seed 3) fell; at
0.6 the DDS platform step (tests/deploy/test_deploy_platform_perception.py) fell at 23-24 s, after
loop stalls, in 4 attempts (2 in a CI rehearsal, 2 of 3 in a run under load) and failed one more run;
at 0.7 it passed 2 runs of 2 under the same load.
All of the above ran on MuJoCo's default friction (soft, pyramidal: stance feet slid well inside their
friction). On the Coulomb floor of stop 46 (g1_control/sim/scene.py grip_physics), at 0.7, draws 20-49
fell: wbc 3 (23, 27, 39), wbc23 2 (39, 43), every one a draw with 10-12 ms command latency; on the soft
floor the same code fell on wbc 8, wbc23 9 of them (measured, one machine).
A floor known to grip better or worse is set per launch file (tracker.foot_friction)."""


@dataclass(frozen=True)
class FootGeometry:
    """Sole rectangle relative to the sole frame origin (m) and friction."""

    x_min_m: float = -0.085
    x_max_m: float = 0.085
    y_min_m: float = -0.025
    y_max_m: float = 0.025
    """The URDF's contact spheres sit at x -0.05..0.12, y +-0.025 (rear) / +-0.03 (front) in the
    ankle-roll link; the sole frame is at x 0.035, so the rectangle is x +-0.085, y +-0.025."""
    cop_margin: float = 0.8
    """Fraction of the rectangle the centre of pressure may use (the edge is a tipping point)."""
    friction: float = DEFAULT_FRICTION
    """The sliding friction coefficient assumed between sole and floor (DEFAULT_FRICTION: why)."""
    torsion_radius_m: float = 0.02
    """The yaw torque a foot may use is mu r fz (Coulomb friction integrated over the contact patch,
    so it scales with mu like the forces do); r is well inside the sole's half-diagonal (0.09 m)."""
    fz_min_n: float = 5.0
    """A stance foot presses with at least this much, so it is not on the verge of lifting."""
    fz_max_n: float = 800.0

    def __post_init__(self) -> None:
        if not (self.x_min_m < 0 < self.x_max_m and self.y_min_m < 0 < self.y_max_m):
            raise WbcConfigError(f"FootGeometry must contain the sole origin; got x [{self.x_min_m}, "
                                 f"{self.x_max_m}] y [{self.y_min_m}, {self.y_max_m}]")
        if not 0 < self.cop_margin <= 1:
            raise WbcConfigError(f"FootGeometry.cop_margin must be in (0, 1]; got {self.cop_margin}")
        if not (np.isfinite(self.friction) and self.friction > 0):
            raise WbcConfigError(f"FootGeometry.friction must be a finite number > 0; got {self.friction}")
        if not 0 <= self.fz_min_n < self.fz_max_n:
            raise WbcConfigError(f"FootGeometry needs 0 <= fz_min_n < fz_max_n; got {self.fz_min_n}, {self.fz_max_n}")

    def corners_local_m(self) -> np.ndarray:
        """(4, 2) usable sole corners (after the CoP margin) in the sole frame."""
        s = self.cop_margin
        return s * np.array([[self.x_min_m, self.y_min_m], [self.x_max_m, self.y_min_m],
                             [self.x_max_m, self.y_max_m], [self.x_min_m, self.y_max_m]])


def wrench_constraint_rows(foot: FootGeometry) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(C, l, u) with l <= C @ wrench <= u for one stance foot (rows: ROWS_PER_FOOT)."""
    mu, s = foot.friction, foot.cop_margin
    inf = 1e20  # proxsuite crashes on true infinities; it treats 1e20 as unbounded
    C = np.zeros((ROWS_PER_FOOT, 6))
    l = np.full(ROWS_PER_FOOT, -inf)
    u = np.zeros(ROWS_PER_FOOT)
    # friction: fx - mu fz <= 0, -fx - mu fz <= 0, same for fy
    C[0, [0, 2]] = (1.0, -mu)
    C[1, [0, 2]] = (-1.0, -mu)
    C[2, [1, 2]] = (1.0, -mu)
    C[3, [1, 2]] = (-1.0, -mu)
    # CoP x: -ty - x_max fz <= 0 and x_min fz + ty <= 0
    C[4, [4, 2]] = (-1.0, -s * foot.x_max_m)
    C[5, [4, 2]] = (1.0, s * foot.x_min_m)
    # CoP y: tx - y_max fz <= 0 and y_min fz - tx <= 0
    C[6, [3, 2]] = (1.0, -s * foot.y_max_m)
    C[7, [3, 2]] = (-1.0, s * foot.y_min_m)
    # yaw torque
    C[8, [5, 2]] = (1.0, -mu * foot.torsion_radius_m)
    C[9, [5, 2]] = (-1.0, -mu * foot.torsion_radius_m)
    # normal force (bounds set per tick by normal_force_bounds)
    C[10, 2] = 1.0
    l[10], u[10] = foot.fz_min_n, foot.fz_max_n
    return C, l, u


def normal_force_bounds(foot: FootGeometry, load_fraction: float) -> tuple[float, float]:
    """(fz_min, fz_max) for a foot carrying up to `load_fraction` (0..1) of its full allowance.

    Ramping the upper bound after touchdown moves the weight onto the new foot over a few
    ticks instead of in one, so torques do not jump when the contact set changes."""
    frac = min(max(float(load_fraction), 0.0), 1.0)
    fz_max = max(foot.fz_min_n + 1.0, frac * foot.fz_max_n)
    return foot.fz_min_n * min(1.0, frac * 4.0), fz_max


def cop_of(wrench: np.ndarray) -> np.ndarray:
    """Centre of pressure (x, y) in the sole frame of a wrench with fz > 0."""
    fz = wrench[2]
    if fz <= 0:
        raise WbcConfigError(f"centre of pressure is undefined for a wrench with fz = {fz} N <= 0")
    return np.array([-wrench[4] / fz, wrench[3] / fz])
