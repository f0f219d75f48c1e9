"""Seeded physics trials for the execution suite and the envelope bench: a scripted command
timeline (velocity, style, pelvis height) run through the one loop builder in lockstep MuJoCo,
optional pushes, and figures taken from the simulator's ground truth only.

    result = run_trial(Trial("carry vx0.5", walk_timeline("carry", (0.5, 0.0, 0.0))))
    result.velocity(1)          # gait-cycle mean of the true heading-frame velocity in segment 1
    result.upper_body_rms(1)    # waist + arm joints, measured vs the tracker's reference posture

Steady state: a segment's first `skip_s` (2 s) are skipped, then whole gait periods (1 s) count.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, cast

import numpy as np

from g1_control.safety.fall import Fall
from g1_control.scene import SceneConfig
from g1_control.teleop.scripted import Segment

if TYPE_CHECKING:
    from g1_control.sim.mujoco_backend import MujocoBackend

GAIT_PERIOD_S = 1.0
"""The holosoma walking policies' gait period: averages over whole periods cancel the sway."""
STEADY_SKIP_S = 2.0


@dataclass(frozen=True)
class Push:
    t_s: float
    force_h_n: tuple[float, float, float]
    """Heading frame at the push's start: x forward, y left (a push "from the front" is -x)."""
    duration_s: float = 0.2


@dataclass
class Trial:
    name: str
    timeline: list[Segment]
    pushes: list[Push] = field(default_factory=list)
    generator: str = "velocity"
    policy: str = "holosoma_loco_ppo"
    envelope_limits: bool = True
    """False: the policy's trained command range instead of the measured envelope (the envelope bench)."""
    tracker: str = "policy"
    """'layer': the tracking layer (walking policy + WBC) that executes goals, at tracker_hz."""
    tracker_hz: float = 50.0
    scene: SceneConfig | None = None


@dataclass
class TrialResult:
    trial: Trial
    log: dict[str, np.ndarray]
    fall: Fall | None
    sim_s: float
    wall_s: float
    tracker_us: tuple[float, float]
    """The tracker stage's p50 and p99 (us) in this run."""
    goals: list[dict] = field(default_factory=list)
    """Goal outcomes from ground truth (g1_control/report/outcomes.py), tracker 'layer' only."""
    layer_cpu: tuple[np.ndarray, np.ndarray] | None = None
    """The tracking layer's act() thread CPU time (s) and what ran (0 policy, 1 WBC, 2 both)."""

    @property
    def fell(self) -> bool:
        return self.fall is not None

    @property
    def real_time_factor(self) -> float:
        return self.sim_s / self.wall_s if self.wall_s > 0 else math.inf

    def segment_bounds(self, index: int) -> tuple[float, float]:
        starts = np.concatenate([[0.0], np.cumsum([s.duration_s for s in self.trial.timeline])])
        return float(starts[index]), float(starts[index + 1])

    def window(self, index: int, skip_s: float = STEADY_SKIP_S) -> np.ndarray:
        """Ticks of segment `index` in steady state: after `skip_s`, whole gait periods only."""
        t0, t1 = self.segment_bounds(index)
        periods = math.floor((t1 - t0 - skip_s) / GAIT_PERIOD_S + 1e-9)
        if periods < 1:
            raise ValueError(f"segment {index} of '{self.trial.name}' is too short for a steady-state window")
        a, b = t0 + skip_s, t0 + skip_s + periods * GAIT_PERIOD_S
        t = self.log["t_s"]
        return (t >= a - 1e-9) & (t < b - 1e-9)

    def velocity(self, index: int) -> np.ndarray:
        """(vx, vy, wz): gait-cycle mean of the true heading-frame velocity over the window."""
        return self.log["velocity_true"][self.window(index)].mean(axis=0)

    def upper_body_rms(self, index: int) -> float:
        """RMS (rad) over waist and arm joints of measured minus the tracker's reference posture."""
        from g1_control.report.results import upper_body_rms

        rms = upper_body_rms(self.log, self.window(index))
        return float("nan") if rms is None else rms

    def pelvis_height(self, index: int) -> float:
        return float(self.log["base_pos_m"][self.window(index), 2].mean())


def walk_timeline(style: str, command: tuple[float, float, float], *, stand_s: float = 1.0, walk_s: float = 6.0,
                  pelvis_height_m: float | None = None) -> list[Segment]:
    """Stand, then walk with `command` (vx, vy, wz); the measured segment is index 1."""
    vx, vy, wz = command
    return [Segment(stand_s, style=style, label="stand", pelvis_height_m=pelvis_height_m),
            Segment(walk_s, vx_mps=vx, vy_mps=vy, wz_radps=wz, style=style, label="walk",
                    pelvis_height_m=pelvis_height_m)]


def trial_launch(trial: Trial):
    from g1_control.launch.schema import LaunchFile

    launch = LaunchFile(name=trial.name.replace(" ", "_"))
    launch.input.timeline = list(trial.timeline)
    launch.generator.type = trial.generator  # type: ignore[assignment]
    launch.tracker.policy = trial.policy
    launch.tracker.envelope_limits = trial.envelope_limits
    launch.tracker.type = trial.tracker  # type: ignore[assignment]
    launch.rates.tracker_hz = trial.tracker_hz
    if trial.scene is not None:
        launch.scene = trial.scene
    launch.validate("trial")
    launch.output.video, launch.output.plot, launch.viewer = False, False, False
    return launch


def heading_to_world(force_h: tuple[float, float, float], quat_wxyz: np.ndarray) -> list[float]:
    from g1_control.rotations import yaw_of

    yaw = yaw_of(quat_wxyz)
    c, s = math.cos(yaw), math.sin(yaw)
    fx, fy, fz = force_h
    return [c * fx - s * fy, s * fx + c * fy, fz]


def run_trial(trial: Trial, *, log_path: Path | None = None, stop_on_fall: bool = True,
              samples: list[np.ndarray] | None = None) -> TrialResult:
    """Run `trial` to its end (or its first fall); `log_path`: also save the log (for a video);
    `samples`: gets the tracker stage's per-tick durations (s) appended."""
    from g1_control.launch.builder import build_loop

    launch = trial_launch(trial)
    loop = build_loop(launch)
    loop.reset()
    watcher = None
    if trial.tracker == "layer":
        from g1_control.report.outcomes import GoalWatcher

        watcher = GoalWatcher(loop)
    duration = launch.total_duration_s
    marks = sorted({p.t_s for p in trial.pushes if p.t_s < duration} | set(np.arange(1.0, duration, 1.0).tolist()))
    marks.append(duration)
    pushes = {p.t_s: p for p in trial.pushes}
    t0 = time.perf_counter()
    try:
        for mark in marks:
            if mark > loop.time_s + 1e-9:
                loop.run(mark - loop.time_s, progress=watcher.tick if watcher is not None else None)
            push = pushes.get(mark)
            if push is not None:
                sim = cast("MujocoBackend", loop.backend)
                sim.push(heading_to_world(push.force_h_n, sim.data.qpos[3:7]), push.duration_s)
            if stop_on_fall and loop.fell:
                break
    finally:
        wall = time.perf_counter() - t0
        loop.backend.close()
    log = loop.log.arrays()
    if log_path is not None:
        log_path.parent.mkdir(parents=True, exist_ok=True)
        np.savez_compressed(log_path, **log)  # type: ignore[arg-type]
    timing = loop.scheduler.report()["tracker"]
    if samples is not None:
        times = loop.scheduler.times["tracker"]
        samples.append(times.samples[: min(times.count, times.capacity)].copy())
    layer_cpu = loop.tracker.cpu_samples() if hasattr(loop.tracker, "cpu_samples") else None
    return TrialResult(trial, log, loop.fall, float(loop.time_s), wall, (timing["p50_us"], timing["p99_us"]),
                       watcher.outcomes() if watcher is not None else [], layer_cpu)
