"""Balance by capture-point feedback on the linear inverted pendulum (LIPM).

With the CoM at constant height z, the horizontal dynamics are c_ddot = w^2 (c - p), w = sqrt(g/z),
p the centre of pressure (ZMP). The divergent component xi = c + c_dot / w obeys
xi_dot = w (xi - p): only it needs feedback, the rest converges by itself. Choosing
    p = p_ref + (1 + k) (xi - xi_ref)
makes the capture-point error decay as exp(-k w t) (Englsberger, Ott, Albu-Schaeffer, "Three-
dimensional bipedal walking control using divergent component of motion", IEEE T-RO 2015).
The CoP is then clipped into the support polygon of the stance feet, and the resulting CoM
acceleration w^2 (c - p) becomes the QP's CoM task.
"""

from __future__ import annotations

import numpy as np

from g1_control.errors import WbcConfigError

GRAVITY_MPS2 = 9.81


def lipm_frequency(com_height_m: float) -> float:
    """Natural frequency w (1/s) of the pendulum at `com_height_m` above the support."""
    if not com_height_m > 0.05:
        raise WbcConfigError(f"LIPM needs a CoM height above 0.05 m over the support; got {com_height_m} m")
    return float(np.sqrt(GRAVITY_MPS2 / com_height_m))


def capture_point(com_xy: np.ndarray, com_vel_xy: np.ndarray, omega: float) -> np.ndarray:
    return com_xy + com_vel_xy / omega


def desired_cop(com_xy: np.ndarray, com_vel_xy: np.ndarray, com_ref_xy: np.ndarray, com_vel_ref_xy: np.ndarray,
                cop_ref_xy: np.ndarray, omega: float, gain: float) -> np.ndarray:
    """CoP that drives the capture point back to the reference's (see module docstring)."""
    xi = capture_point(com_xy, com_vel_xy, omega)
    xi_ref = capture_point(com_ref_xy, com_vel_ref_xy, omega)
    return cop_ref_xy + (1.0 + gain) * (xi - xi_ref)


def convex_hull(points: np.ndarray) -> np.ndarray:
    """Counter-clockwise convex hull of 2D points (Andrew's monotone chain)."""
    pts = sorted(map(tuple, np.asarray(points, dtype=float).tolist()))  # Python floats: numpy scalars cost ~10x
    if len(pts) <= 2:
        return np.array(pts)

    def cross(o, a, b):
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    lower: list[tuple] = []
    upper: list[tuple] = []
    for p in pts:
        while len(lower) >= 2 and cross(lower[-2], lower[-1], p) <= 0:
            lower.pop()
        lower.append(p)
    for p in reversed(pts):
        while len(upper) >= 2 and cross(upper[-2], upper[-1], p) <= 0:
            upper.pop()
        upper.append(p)
    return np.array(lower[:-1] + upper[:-1])


def project_into_polygon(point: np.ndarray, hull: np.ndarray) -> np.ndarray:
    """`point` if inside the CCW convex polygon `hull`, else the closest point on its boundary."""
    n = len(hull)
    inside = True
    corners, (px, py) = np.asarray(hull, dtype=float).tolist(), np.asarray(point, dtype=float).tolist()  # Python floats: numpy scalars cost ~10x
    for i in range(n):
        (ax, ay), (bx, by) = corners[i], corners[(i + 1) % n]
        if (bx - ax) * (py - ay) - (by - ay) * (px - ax) < 0:
            inside = False
            break
    if inside:
        return np.array(point, dtype=float)
    best: np.ndarray | None = None
    best_d = np.inf
    for i in range(n):
        a, b = hull[i], hull[(i + 1) % n]
        ab = b - a
        t = min(max(float(np.dot(point - a, ab) / max(np.dot(ab, ab), 1e-12)), 0.0), 1.0)
        c = a + t * ab
        d = float(np.sum((point - c) ** 2))
        if d < best_d:
            best, best_d = c, d
    assert best is not None  # an empty hull returned above; a NaN point counts as inside
    return best


def support_polygon(sole_pos_w: np.ndarray, sole_rot_w: np.ndarray, corners_local: np.ndarray,
                    stance: np.ndarray) -> np.ndarray:
    """Convex hull (world xy) of the usable sole corners of the stance feet."""
    pts = [sole_pos_w[i, :2] + corners_local @ sole_rot_w[i][:2, :2].T for i in range(2) if stance[i]]
    if not pts:
        raise WbcConfigError("support polygon requested with no foot in stance")
    return convex_hull(np.vstack(pts))
