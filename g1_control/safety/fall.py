"""What counts as a fall, judged the same way by every run summary and bench.

A fall is the first of:
  - the pelvis tilted beyond the safety layer's tilt limit (SafetyConfig.max_tilt_rad);
  - the pelvis below `min_pelvis_height_m` above the ground;
  - any body other than the feet (and the bodies a task allows, e.g. the hands) touching the ground.

The evidence comes from what the robot has: in simulation the simulator's own state (the pelvis
position and MuJoCo's contacts, Backend.ground_contacts); on the robot the IMU's tilt and the
pelvis height the state estimator computes from leg kinematics (EstimatedState.pelvis_height_m).
The monitor keeps judging after the safety layer tripped for another reason: a robot that was
damped for a joint over-speed and then collapsed has fallen.
"""

from __future__ import annotations

from dataclasses import dataclass

from g1_control.errors import SafetyConfigError
from g1_control.robot import g1
from g1_control.rotations import tilt_rad


@dataclass(frozen=True)
class FallConfig:
    min_pelvis_height_m: float = 0.4
    """Below this pelvis height above the ground the robot counts as fallen (the G1 walks at
    0.75-0.79 m; the deepest crouch any tracker is asked for is 0.45 m)."""
    allowed_contacts: tuple[str, ...] = ()
    """Bodies besides the feet that may touch the ground (e.g. the hands, where a task allows)."""

    def validate(self, where: str = "fall") -> None:
        if not 0.0 < self.min_pelvis_height_m < g1.DEFAULT_PELVIS_HEIGHT_M:
            raise SafetyConfigError(f"{where}.min_pelvis_height_m is {self.min_pelvis_height_m}; it must lie in "
                                    f"(0, {g1.DEFAULT_PELVIS_HEIGHT_M}) m")


@dataclass(frozen=True)
class Fall:
    t_s: float
    kind: str
    """"tilt", "pelvis_low" or "body_contact"."""
    detail: str

    def __str__(self) -> str:
        return f"{self.detail} at {self.t_s:.2f} s"


class FallMonitor:
    """Latches the first fall sign. update() runs once per control tick (allocation-free when
    nothing happens)."""

    def __init__(self, config: FallConfig | None = None, max_tilt_rad: float = 1.0):
        self.config = config or FallConfig()
        self.max_tilt_rad = max_tilt_rad
        self.fall: Fall | None = None

    def reset(self) -> None:
        self.fall = None

    def update(self, t_s: float, imu_quat_wxyz, pelvis_height_m: float | None,
               contacts: tuple[str, ...] | None) -> Fall | None:
        """The fall, if this tick shows the first sign of one (None otherwise and after the first).

        pelvis_height_m: above the ground (None: unknown); contacts: robot bodies other than the
        feet touching the ground now (Backend.ground_contacts; None: no contact sensing)."""
        if self.fall is not None:
            return None
        tilt = tilt_rad(imu_quat_wxyz)
        if tilt > self.max_tilt_rad:
            self.fall = Fall(t_s, "tilt", f"pelvis tilted {tilt:.2f} rad (limit {self.max_tilt_rad:.2f})")
        elif pelvis_height_m is not None and pelvis_height_m < self.config.min_pelvis_height_m:
            self.fall = Fall(t_s, "pelvis_low", f"pelvis at {pelvis_height_m:.2f} m "
                                                f"(limit {self.config.min_pelvis_height_m:.2f})")
        elif contacts:
            bodies = [b for b in contacts if b not in self.config.allowed_contacts]
            if bodies:
                self.fall = Fall(t_s, "body_contact", f"{', '.join(bodies)} on the ground")
        return self.fall
