"""Physics rollouts of the locomotion tracker under randomized commands, one upper-body style
per rollout, recorded as MotionClips.

The loop is the project's own, built from a launch file like every other (MuJoCo in lockstep,
the velocity generator with the style's pose, holosoma's loco policy, the safety filter), so the recorded motion is what the robot's physics and policy produce: real gait
timing, foot contacts and speed response (docs/robot_facts.md), not an idealized gait. The styled-walking tracker
(g1_control/trackers/styled.py) holds the style's arms and keeps the torso up (waist pitch within
a few 0.1 rad: the lean that balances arms held forward) instead of the 0.5 rad sag the earlier
upper-body override recorded. Frames after a fall are dropped.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from g1_control.generator.styles import ROLLOUT_STYLES, UpperBodyStyle
from g1_control.launch.builder import build_loop, timeline_of
from g1_control.launch.schema import LaunchFile
from g1_control.motion.clip import MotionClip
from g1_control.motion.interpolation import interpolate_positions, interpolate_quaternions
from g1_control.report.results import upper_body_rms
from g1_control.robot import g1
from g1_control.teleop.scripted import RandomTimelineConfig


@dataclass
class RolloutConfig:
    duration_s: float = 60.0
    seed: int = 0
    fps: float = 30.0
    segment_s: tuple[float, float] = (1.5, 5.0)
    vx_mps: tuple[float, float] = (-0.4, 0.8)
    vy_mps: tuple[float, float] = (-0.3, 0.3)
    wz_radps: tuple[float, float] = (-0.8, 0.8)
    stand_probability: float = 0.2


def rollout_launch(style: UpperBodyStyle, config: RolloutConfig) -> LaunchFile:
    """The rollout as a launch file: seeded random commands with one upper-body style, the velocity
    generator (the style's pose, tracked with the upper-body override), holosoma's loco policy."""
    launch = LaunchFile(name=f"rollout_{style.name}_s{config.seed}", duration_s=config.duration_s)
    launch.input.type = "random"
    launch.input.random = RandomTimelineConfig(
        seed=config.seed, segment_s=config.segment_s, vx_mps=config.vx_mps, vy_mps=config.vy_mps,
        wz_radps=config.wz_radps, stand_probability=config.stand_probability, style=style.name)
    launch.tracker.policy = "holosoma_loco_ppo"
    launch.output.video, launch.output.plot, launch.viewer = False, False, False
    return launch


def random_commands(config: RolloutConfig) -> list[tuple[float, float, float, float]]:
    """(start_s, vx, vy, wz) segments: stands, straight walks, sidesteps, turns and mixes."""
    out, t = [], 0.0
    for seg in timeline_of(rollout_launch(ROLLOUT_STYLES["default"], config)):
        out.append((t, seg.vx_mps, seg.vy_mps, seg.wz_radps))
        t += seg.duration_s
    return out


def pose_figures(log: dict[str, np.ndarray], n: int) -> dict[str, float]:
    """How well the recording holds the style's pose over its first n ticks: RMS of the waist and
    arm joints against the pose the tracker was given (the style's plan), and the mean waist pitch
    (the plan's is 0; the earlier override let it sag to the 0.52 rad joint limit)."""
    rows = np.arange(len(log["t_s"])) < n
    rms = upper_body_rms(log, rows)
    if rms is None:
        return {}
    return {"upper_body_rms_rad": rms,
            "waist_pitch_mean_rad": float(log["q_rad"][:n, g1.JOINT_INDEX["waist_pitch_joint"]].mean())}


def record_rollout(style: UpperBodyStyle, config: RolloutConfig) -> tuple[MotionClip | None, dict]:
    """One rollout; returns (clip at config.fps or None if it fell at once, info)."""
    launch = rollout_launch(style, config)
    segments = random_commands(config)
    loop = build_loop(launch, log_capacity=int(config.duration_s * 50) + 10)
    loop.reset()
    # Run in 1 s pieces so that a fall stops the recording early.
    for _ in range(int(np.ceil(config.duration_s))):
        loop.run(1.0)
        if loop.faulted:
            break
    log = loop.log.arrays()
    loop.backend.close()
    valid = ~np.isnan(log["base_pos_m"][:, 0])
    trip = loop.safety.trip_event  # not None exactly when loop.faulted
    if trip is not None:
        # Damped frames are not motion anyone commanded; before a fall, the last 2 s were
        # already a loss of balance.
        valid &= log["t_s"] < trip.t_s - (2.0 if loop.fell else 0.0)
    n = int(np.argmin(valid)) if not valid.all() else len(valid)
    info = {"style": style.name, "seed": config.seed, "fell": bool(loop.fell),
            "fault": trip.kind.value if trip is not None else None, "recorded_s": float(n / 50.0),
            "commands": segments, **pose_figures(log, n)}
    if n < 60:
        return None, info
    src_fps = 50.0
    times = np.arange(int((n - 1) / src_fps * config.fps) + 1) / config.fps
    root_pos = interpolate_positions(log["base_pos_m"][:n], src_fps, times)
    root_quat = interpolate_quaternions(log["base_quat_wxyz"][:n], src_fps, times)
    joints = interpolate_positions(log["q_rad"][:n], src_fps, times)
    clip = MotionClip.from_joint_trajectory(config.fps, root_pos, root_quat, joints,
                                            source=f"rollout_{style.name}_s{config.seed}", style=style.name,
                                            tags=("rollout", "physics"))
    return clip, info
