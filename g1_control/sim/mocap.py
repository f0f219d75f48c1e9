"""A motion-capture system and a perception system played from the simulator's ground truth, sampled
at `rate_hz`, with Gaussian noise, a latency and random dropouts, seeded. SimulatedMocap: the pelvis
pose in the world; SimulatedPerception: the scene's boxes (and platforms' top faces) in the robot's
heading frame (origin at the pelvis, x along its heading), as a camera on the robot sees them.

    mocap = SimulatedMocap(MocapConfig(rate_hz=100, noise_m=0.01, latency_s=0.05, dropout=0.1))
    for stamp_s, position_m, quat_wxyz in mocap.sample(t_s, base_pos_w_m, imu_quat_wxyz):
        ...   # the poses whose latency has passed by t_s, each stamped when it was measured

`g1 sim-robot --mocap` publishes these on a PoseStamped topic (the wall clock); `g1 bench odometry`
feeds them to the fusion in lockstep (simulated time).
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass

import numpy as np


@dataclass
class MocapConfig:
    rate_hz: float = 100.0
    noise_m: float = 0.0
    """Standard deviation of the position noise, per axis (x, y, z)."""
    noise_rad: float = 0.0
    """Standard deviation of the heading noise."""
    latency_s: float = 0.0
    dropout: float = 0.0
    """Probability that a pose is lost."""
    seed: int = 0

    def validate(self) -> MocapConfig:
        if not (math.isfinite(self.rate_hz) and 0 < self.rate_hz <= 1000):
            raise ValueError(f"mocap rate_hz: {self.rate_hz} is outside (0, 1000]")
        for name in ("noise_m", "noise_rad", "latency_s"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value >= 0):
                raise ValueError(f"mocap {name}: must be >= 0, got {value}")
        if not 0 <= self.dropout < 1:
            raise ValueError(f"mocap dropout: {self.dropout} is outside [0, 1)")
        return self


def _rot_z(quat_wxyz: np.ndarray, angle: float) -> np.ndarray:
    c, s = math.cos(angle / 2), math.sin(angle / 2)
    w, x, y, z = (float(v) for v in quat_wxyz)
    return np.array([c * w - s * z, c * x - s * y, c * y + s * x, c * z + s * w])


class SimulatedMocap:
    """See the module docstring."""

    def __init__(self, config: MocapConfig):
        self.config = config.validate()
        self._rng = np.random.default_rng(config.seed)
        self._next_s: float | None = None
        self._pending: deque[tuple[float, float, np.ndarray, np.ndarray]] = deque()
        self.measured = self.dropped = 0

    def sample(self, t_s: float, position_m: np.ndarray, quat_wxyz: np.ndarray
               ) -> list[tuple[float, np.ndarray, np.ndarray]]:
        """Measure at t_s when a sample is due; return the poses released by t_s (stamp, position, quat)."""
        cfg = self.config
        if self._next_s is None:
            self._next_s = t_s
        if t_s >= self._next_s - 1e-9:
            self._next_s += 1.0 / cfg.rate_hz
            if self._next_s <= t_s:
                self._next_s = t_s + 1.0 / cfg.rate_hz
            self.measured += 1
            if self._rng.random() < cfg.dropout:
                self.dropped += 1
            else:
                pos = np.asarray(position_m, dtype=float) + self._rng.normal(0.0, cfg.noise_m, 3) * (cfg.noise_m > 0)
                quat = _rot_z(quat_wxyz, float(self._rng.normal(0.0, cfg.noise_rad)) if cfg.noise_rad > 0 else 0.0)
                self._pending.append((t_s + cfg.latency_s, t_s, pos, quat))
        out = []
        while self._pending and self._pending[0][0] <= t_s + 1e-9:
            _, stamp, pos, quat = self._pending.popleft()
            out.append((stamp, pos, quat))
        return out


class SimulatedPerception:
    """Objects (boxes, platforms' top faces) seen from the robot: name -> (position, quat wxyz) in the heading frame, each frame
    stamped when seen and released `latency_s` later; a dropped frame loses every object in it."""

    def __init__(self, config: MocapConfig):
        self.config = config.validate()
        self._rng = np.random.default_rng(config.seed)
        self._next_s: float | None = None
        self._pending: deque[tuple[float, float, dict]] = deque()
        self.measured = self.dropped = 0

    def sample(self, t_s: float, base_pos_w_m: np.ndarray, base_quat_wxyz: np.ndarray,
               objects_w: dict[str, tuple[np.ndarray, np.ndarray]]) -> list[tuple[float, dict]]:
        cfg = self.config
        if self._next_s is None:
            self._next_s = t_s
        if t_s >= self._next_s - 1e-9:
            self._next_s = max(self._next_s + 1.0 / cfg.rate_hz, t_s)
            self.measured += 1
            if self._rng.random() < cfg.dropout:
                self.dropped += 1
            else:
                w, x, y, z = (float(v) for v in base_quat_wxyz)
                yaw = math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))
                c, s = math.cos(yaw), math.sin(yaw)
                seen = {}
                for name, (pos, quat) in objects_w.items():
                    d = np.asarray(pos, dtype=float) - np.asarray(base_pos_w_m, dtype=float)
                    rel = np.array([c * d[0] + s * d[1], -s * d[0] + c * d[1], d[2]])
                    rel += self._rng.normal(0.0, cfg.noise_m, 3)
                    turn = -yaw + float(self._rng.normal(0.0, cfg.noise_rad))
                    seen[name] = (rel, _rot_z(quat, turn))
                self._pending.append((t_s + cfg.latency_s, t_s, seen))
        out = []
        while self._pending and self._pending[0][0] <= t_s + 1e-9:
            _, stamp, seen = self._pending.popleft()
            out.append((stamp, seen))
        return out


__all__ = ["MocapConfig", "SimulatedMocap", "SimulatedPerception"]
