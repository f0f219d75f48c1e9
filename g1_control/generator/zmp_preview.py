"""CoM plans from a ZMP reference by preview control of the cart-table model.

Kajita et al., "Biped walking pattern generation by using preview control of zero-moment point",
ICRA 2003. Per horizontal axis the state is (c, c_dot, c_ddot) with jerk as input, and the output
is the ZMP p = c - (z_c / g) c_ddot. An LQR with preview of the future ZMP reference gives
    u_k = -K x_k + sum_{j=1..N} f_j p_ref[k + j],
with K and f_j from the discrete Riccati solution (Katayama et al. 1985, the non-integral form).
"""

from __future__ import annotations

import numpy as np

from g1_control.errors import WbcConfigError

GRAVITY_MPS2 = 9.81


class ZmpPreviewController:
    def __init__(self, dt_s: float, com_height_m: float, preview_s: float = 1.6,
                 zmp_weight: float = 1.0, jerk_weight: float = 1e-6):
        if dt_s <= 0 or com_height_m <= 0 or preview_s < dt_s:
            raise WbcConfigError(f"ZMP preview needs dt_s > 0, com_height_m > 0, preview_s >= dt_s; got "
                                 f"{dt_s}, {com_height_m}, {preview_s}")
        from scipy.linalg import solve_discrete_are

        T = dt_s
        self.dt_s = dt_s
        self.A = np.array([[1.0, T, T * T / 2], [0.0, 1.0, T], [0.0, 0.0, 1.0]])
        self.B = np.array([[T**3 / 6], [T * T / 2], [T]])
        self.C = np.array([[1.0, 0.0, -com_height_m / GRAVITY_MPS2]])
        Q = zmp_weight * self.C.T @ self.C
        R = np.array([[jerk_weight]])
        P = solve_discrete_are(self.A, self.B, Q, R)
        inv = 1.0 / (R + self.B.T @ P @ self.B)[0, 0]
        self.K = inv * (self.B.T @ P @ self.A)  # (1, 3)
        Ac = self.A - self.B @ self.K
        self.n_preview = round(preview_s / dt_s)
        f = np.zeros(self.n_preview)
        X = self.C.T * zmp_weight  # (3, 1): (Ac^T)^(j-1) C^T Q
        for j in range(self.n_preview):
            f[j] = inv * (self.B.T @ X)[0, 0]
            X = Ac.T @ X
        self.f = f

    def plan(self, zmp_ref: np.ndarray, initial_com: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """CoM position, velocity, acceleration (n, d) following `zmp_ref` (n, d) sampled at dt_s.
        The reference is held at its last value beyond its end, for the preview."""
        zmp_ref = np.asarray(zmp_ref, dtype=float)
        n, dims = zmp_ref.shape
        padded = np.vstack([zmp_ref, np.repeat(zmp_ref[-1:], self.n_preview + 1, axis=0)])
        pos, vel, acc = np.zeros((n, dims)), np.zeros((n, dims)), np.zeros((n, dims))
        for d in range(dims):
            x = np.array([initial_com[d], 0.0, 0.0])
            for k in range(n):
                pos[k, d], vel[k, d], acc[k, d] = x
                u = -(self.K @ x)[0] + self.f @ padded[k + 1:k + 1 + self.n_preview, d]
                x = self.A @ x + self.B[:, 0] * u
        return pos, vel, acc

    def zmp_of(self, pos: np.ndarray, acc: np.ndarray) -> np.ndarray:
        """The cart-table ZMP of a CoM trajectory."""
        return pos + self.C[0, 2] * acc
