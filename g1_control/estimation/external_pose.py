"""An external world pose (motion capture, SLAM) fused with the leg odometry (pose.py).

A pose arrives with the time it was measured (its stamp), later than that (latency). It is carried
to now with the odometry's own motion since the stamp (latency compensation: the odometry's pose at
the stamp is interpolated from a short history), then checked and, if accepted, the fused pose is
pulled toward it (a complementary filter: the odometry carries the pose between external poses, the
external pose removes its drift with time constant `correction_tau_s`). Poses are refused by name,
counted per reason, with the last reason kept as a message:

  stale     older than max_age_s when it is used (or older than the odometry history)
  future    stamped more than FUTURE_SLACK_S after now (the publisher's clock is not this host's)
  jump      farther than max_jump_m (or max_jump_rad in heading) from the fused pose
  invalid   a non-finite field

Recovery after an outage: while no pose arrives the odometry drifts, and the first poses after the
outage may all lie farther than max_jump_m from the fused pose; without recovery they would be
refused for the rest of the run. A single wild pose (a marker swap, a SLAM relocalisation glitch) is
a jump; `reacquire_poses` consecutive jumping poses that agree with each other (their innovations
within `reacquire_tolerance_m` / `reacquire_tolerance_rad` of the first one's) are the robot's
pose, and the fused pose is set to the latest of them (counted as `reacquired`, with the size of the
correction). `reacquire_poses: 0` never re-acquires.

Frames: `frame: start` (the default) aligns the external frame to the run's start frame on the first
accepted pose (the external system's origin may be anywhere); `frame: scene` takes the poses as given
in the launch file's scene frame (motion capture calibrated to the scene).

    fusion = PoseFusion(ExternalPoseConfig(max_age_s=0.3, max_jump_m=0.3))
    fused = fusion.update(odometry_pose)                 # every estimator tick: (t, x, y, yaw)
    fusion.measure(PoseSample(stamp_s, x, y, yaw))        # whenever a pose arrives (loop clock)
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass, field
from typing import Literal

from g1_control.errors import LaunchFileError
from g1_control.rotations import wrap_angle

FUTURE_SLACK_S = 0.05
"""A stamp may be this much after now (clock jitter between the stamping and the reading thread)."""
HISTORY_S = 2.0
"""Odometry poses kept for latency compensation."""
FRAMES = ("start", "scene")
REASONS = ("stale", "future", "jump", "invalid")


@dataclass
class ExternalPoseConfig:
    """launch file `estimation.external_pose`: where the pose comes from and how it is trusted."""

    topic: str = "mocap/pose"
    """ROS 2 topic name of a geometry_msgs/PoseStamped (on DDS: rt/<topic>)."""
    interface: str | None = None
    """Network interface of the pose's publisher (always named; lo: this computer)."""
    domain: int = 0
    partition: str | None = None
    """DDS partition; default: the robot link's (backend.partition, g1 deploy --partition)."""
    max_age_s: float = 0.3
    """Older poses are refused (stale); latency below this is compensated by the odometry."""
    max_jump_m: float = 0.3
    """A latency-compensated pose farther than this from the fused pose is refused (jump)."""
    max_jump_rad: float = 0.5
    correction_tau_s: float = 0.5
    """Time constant of the pull toward the external pose (seconds of poses, not of ticks)."""
    reacquire_poses: int = 10
    """After this many consecutive jumping poses that agree with each other, take the latest (0: never)."""
    reacquire_tolerance_m: float = 0.05
    reacquire_tolerance_rad: float = 0.1
    frame: Literal["start", "scene"] = "start"
    """start: align the external frame to the start frame on the first pose; scene: poses are in the scene frame."""
    start_in_scene: list[float] | None = None
    """frame scene: the robot's start (x, y, yaw) in the scene's frame, from scene.robot_start
    (g1_control/launch/start_pose.py); poses are mapped from the scene's frame into the start frame."""

    def validate(self, where: str) -> None:
        from g1_control.hardware.ros2.topics import check_topic_name

        if not isinstance(self.interface, str) or not self.interface:
            raise LaunchFileError(f"{where}.interface: an external pose input must name the network interface of "
                                  "its publisher (lo for this computer, e.g. g1 sim-robot --mocap)")
        problem = check_topic_name(self.topic)
        if problem:
            raise LaunchFileError(f"{where}.topic: {problem}")
        if not 0 <= self.domain <= 232:
            raise LaunchFileError(f"{where}.domain: {self.domain} is not a DDS domain id (0..232)")
        if isinstance(self.reacquire_poses, bool) or not isinstance(self.reacquire_poses, int) \
                or not 0 <= self.reacquire_poses <= 1000:
            raise LaunchFileError(f"{where}.reacquire_poses: must be a whole number of poses 0..1000 (0: never "
                                  f"re-acquire after an outage), got {self.reacquire_poses!r}")
        for name in ("max_age_s", "max_jump_m", "max_jump_rad", "correction_tau_s", "reacquire_tolerance_m",
                     "reacquire_tolerance_rad"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value) or value <= 0:
                raise LaunchFileError(f"{where}.{name}: must be a positive number, got {value!r}")
        if self.max_age_s > HISTORY_S:
            raise LaunchFileError(f"{where}.max_age_s: {self.max_age_s} s is longer than the {HISTORY_S:g} s of "
                                  "odometry kept to compensate latency")
        if self.reacquire_tolerance_m >= self.max_jump_m:
            raise LaunchFileError(f"{where}.reacquire_tolerance_m: {self.reacquire_tolerance_m} m must be below "
                                  f"max_jump_m ({self.max_jump_m} m), or a jumping pose would agree with anything")
        start = self.start_in_scene
        if start is not None and (not isinstance(start, list | tuple) or len(start) != 3
                                  or not all(isinstance(v, int | float) and math.isfinite(v) for v in start)):
            raise LaunchFileError(f"{where}.start_in_scene: expected [x, y, yaw] (3 finite numbers), got {start!r}")
        if self.frame not in FRAMES:
            raise LaunchFileError(f"{where}.frame: '{self.frame}' is not one of {', '.join(FRAMES)}")


@dataclass(frozen=True)
class PoseSample:
    """A planar pose measured at `stamp_s` (the loop's clock)."""

    stamp_s: float
    x_m: float
    y_m: float
    yaw_rad: float


@dataclass(frozen=True)
class Planar:
    t_s: float
    x_m: float
    y_m: float
    yaw_rad: float

    def compose(self, dx: float, dy: float, dyaw: float) -> tuple[float, float, float]:
        """This pose moved by (dx, dy, dyaw) given in its own frame."""
        c, s = math.cos(self.yaw_rad), math.sin(self.yaw_rad)
        return self.x_m + c * dx - s * dy, self.y_m + s * dx + c * dy, float(wrap_angle(self.yaw_rad + dyaw))

    def relative(self, other: Planar) -> tuple[float, float, float]:
        """`other` in this pose's frame (this^-1 * other)."""
        c, s = math.cos(self.yaw_rad), math.sin(self.yaw_rad)
        dx, dy = other.x_m - self.x_m, other.y_m - self.y_m
        return c * dx + s * dy, -s * dx + c * dy, float(wrap_angle(other.yaw_rad - self.yaw_rad))


@dataclass
class FusionCounters:
    accepted: int = 0
    rejected: dict[str, int] = field(default_factory=lambda: dict.fromkeys(REASONS, 0))
    last_rejection: str = ""
    """Why the last refused pose was refused (empty: none refused)."""
    max_correction_m: float = 0.0
    """The largest accepted innovation (latency-compensated pose minus fused pose)."""
    reacquired: int = 0
    """Times the fused pose was reset to agreeing poses after an outage (see the module docstring)."""
    max_reacquire_m: float = 0.0
    """The largest such reset."""


def _scene_to_start(start: list[float] | None) -> Planar:
    """The scene frame seen from the start frame of a robot starting at `start` (x, y, yaw) in it."""
    if start is None:
        return Planar(0.0, 0.0, 0.0, 0.0)
    x, y, yaw = (float(v) for v in start)
    c, s = math.cos(yaw), math.sin(yaw)
    return Planar(0.0, -(c * x + s * y), -(-s * x + c * y), float(wrap_angle(-yaw)))


class PoseFusion:
    """See the module docstring."""

    def __init__(self, config: ExternalPoseConfig):
        self.config = config
        self.counters = FusionCounters()
        self._history: deque[Planar] = deque()
        self.fused: Planar | None = None
        self._last_odometry: Planar | None = None
        self._align: Planar | None = _scene_to_start(config.start_in_scene) if config.frame == "scene" else None
        self._last_accepted_stamp: float | None = None
        self._jumps: list[tuple[float, float, float]] = []
        """Innovations (ex, ey, eyaw) of the consecutive jumping poses since the last accepted one."""

    def update(self, odometry: Planar) -> Planar:
        """The fused pose after the odometry moved to `odometry` (start frame)."""
        if self.fused is None or self._last_odometry is None:
            self.fused = odometry
        else:
            self.fused = Planar(odometry.t_s, *self.fused.compose(*self._last_odometry.relative(odometry)))
        self._last_odometry = odometry
        h = self._history
        h.append(odometry)
        while h and h[0].t_s < odometry.t_s - HISTORY_S:
            h.popleft()
        return self.fused

    def odometry_at(self, t_s: float) -> Planar | None:
        """The odometry's pose at `t_s` (linear between samples), None outside the history."""
        h = self._history
        if not h or t_s < h[0].t_s or t_s > h[-1].t_s:
            return None
        lo, hi = 0, len(h) - 1
        while hi - lo > 1:
            mid = (lo + hi) // 2
            if h[mid].t_s <= t_s:
                lo = mid
            else:
                hi = mid
        a, b = h[lo], h[hi]
        f = 0.0 if b.t_s == a.t_s else (t_s - a.t_s) / (b.t_s - a.t_s)
        return Planar(t_s, a.x_m + f * (b.x_m - a.x_m), a.y_m + f * (b.y_m - a.y_m),
                      wrap_angle(a.yaw_rad + f * wrap_angle(b.yaw_rad - a.yaw_rad)))

    def _refuse(self, reason: str, message: str) -> None:
        self.counters.rejected[reason] += 1
        self.counters.last_rejection = f"{reason}: {message}"

    def measure(self, sample: PoseSample) -> bool:
        """Take one external pose; True when it was accepted (else counters say why)."""
        cfg = self.config
        if self.fused is None or self._last_odometry is None:
            self._refuse("stale", "a pose before the first odometry update")
            return False
        now = self._last_odometry.t_s
        values = (sample.stamp_s, sample.x_m, sample.y_m, sample.yaw_rad)
        if not all(math.isfinite(v) for v in values):
            self._refuse("invalid", f"non-finite field in {values}")
            return False
        age = now - sample.stamp_s
        if age < -FUTURE_SLACK_S:
            self._refuse("future", f"stamped {-age:.3f} s after now (is the publisher's clock synchronised?)")
            return False
        if age > cfg.max_age_s:
            self._refuse("stale", f"{age:.3f} s old (max_age_s {cfg.max_age_s:g})")
            return False
        then = self.odometry_at(min(sample.stamp_s, now))
        if then is None:
            self._refuse("stale", f"stamped {age:.3f} s ago, before the odometry history")
            return False
        measured = Planar(sample.stamp_s, sample.x_m, sample.y_m, sample.yaw_rad)
        if self._align is None:  # frame start: the first pose says where the external frame lies
            # align = fused pose at the stamp * measured^-1: maps the external frame into the start frame
            fused_then = Planar(then.t_s, *self.fused.compose(*self._last_odometry.relative(then)))
            yaw = wrap_angle(fused_then.yaw_rad - measured.yaw_rad)
            c, s = math.cos(yaw), math.sin(yaw)
            self._align = Planar(0.0, fused_then.x_m - (c * measured.x_m - s * measured.y_m),
                                 fused_then.y_m - (s * measured.x_m + c * measured.y_m), yaw)
        start = Planar(sample.stamp_s, *self._align.compose(measured.x_m, measured.y_m, measured.yaw_rad))
        now_x, now_y, now_yaw = start.compose(*then.relative(self._last_odometry))
        fused = self.fused
        ex, ey, eyaw = now_x - fused.x_m, now_y - fused.y_m, wrap_angle(now_yaw - fused.yaw_rad)
        distance = math.hypot(ex, ey)
        if distance > cfg.max_jump_m or abs(eyaw) > cfg.max_jump_rad:
            if self._reacquire(ex, ey, eyaw):
                self._last_accepted_stamp = sample.stamp_s
                self.fused = Planar(fused.t_s, now_x, now_y, now_yaw)
                self.counters.accepted += 1
                self.counters.reacquired += 1
                self.counters.max_reacquire_m = max(self.counters.max_reacquire_m, distance)
                return True
            self._refuse("jump", f"{distance:.3f} m / {math.degrees(eyaw):.1f} deg from the fused pose "
                                 f"(max_jump_m {cfg.max_jump_m:g}, max_jump_rad {cfg.max_jump_rad:g})")
            return False
        self._jumps.clear()
        gap = cfg.correction_tau_s if self._last_accepted_stamp is None else \
            max(0.0, sample.stamp_s - self._last_accepted_stamp)
        gain = gap / (cfg.correction_tau_s + gap)
        self._last_accepted_stamp = sample.stamp_s
        self.fused = Planar(fused.t_s, fused.x_m + gain * ex, fused.y_m + gain * ey,
                            wrap_angle(fused.yaw_rad + gain * eyaw))
        self.counters.accepted += 1
        self.counters.max_correction_m = max(self.counters.max_correction_m, distance)
        return True

    def _reacquire(self, ex: float, ey: float, eyaw: float) -> bool:
        """Count one jumping pose; True when it completes a run of `reacquire_poses` agreeing ones."""
        cfg = self.config
        if cfg.reacquire_poses <= 0:
            return False
        if self._jumps:
            fx, fy, fyaw = self._jumps[0]
            if math.hypot(ex - fx, ey - fy) > cfg.reacquire_tolerance_m or \
                    abs(wrap_angle(eyaw - fyaw)) > cfg.reacquire_tolerance_rad:
                self._jumps.clear()  # disagrees with the run so far: it starts a new one
        self._jumps.append((ex, ey, eyaw))
        if len(self._jumps) < cfg.reacquire_poses:
            return False
        self._jumps.clear()
        return True

    def describe(self) -> str:
        c = self.counters
        refused = ", ".join(f"{n} {r}" for r, n in c.rejected.items() if n) or "none"
        out = f"external pose: {c.accepted} accepted, refused: {refused}"
        if c.reacquired:
            out += f", re-acquired {c.reacquired}x after an outage (largest reset {c.max_reacquire_m:.2f} m)"
        return out + (f" (last: {c.last_rejection})" if c.last_rejection else "")


__all__ = ["FRAMES", "REASONS", "ExternalPoseConfig", "FusionCounters", "Planar", "PoseFusion", "PoseSample"]
