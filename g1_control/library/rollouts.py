"""Physics rollouts of the locomotion tracker under randomized commands, one upper-body style
per rollout, recorded as MotionClips.

The loop is the project's own ControlLoop in lockstep (MuJoCo, holosoma loco policy, safety
filter), so the recorded motion is what the robot's physics and policy produce: real gait
timing, foot contacts and the ~80 % speed response (FACTS.md), not an idealized gait. Frames
after a fall are dropped.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from g1_control.generator.velocity import CopyRetargeter
from g1_control.interfaces import Generator, InputDevice
from g1_control.library.styles import UpperBodyStyle
from g1_control.motion.clip import MotionClip
from g1_control.motion.resample import interpolate_positions, interpolate_quaternions
from g1_control.robot import g1
from g1_control.types import Command, JointReference, KinematicReference, RobotState


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


def random_commands(config: RolloutConfig) -> list[tuple[float, float, float, float]]:
    """(start_s, vx, vy, wz) segments: stands, straight walks, sidesteps, turns and mixes."""
    from g1_control.launch.schema import RandomTimelineConfig
    from g1_control.teleop.scripted import random_timeline

    cfg = RandomTimelineConfig(seed=config.seed, segment_s=config.segment_s, vx_mps=config.vx_mps,
                               vy_mps=config.vy_mps, wz_radps=config.wz_radps,
                               stand_probability=config.stand_probability)
    out, t = [], 0.0
    for seg in random_timeline(cfg, config.duration_s):
        out.append((t, seg.vx_mps, seg.vy_mps, seg.wz_radps))
        t += seg.duration_s
    return out


class _TimelineInput(InputDevice):
    def __init__(self, segments, clock):
        self.starts = np.array([s[0] for s in segments])
        self.commands = [Command(vx_mps=s[1], vy_mps=s[2], wz_radps=s[3]) for s in segments]
        self.clock = clock

    def poll(self) -> Command:
        return self.commands[int(np.searchsorted(self.starts, self.clock(), side="right")) - 1]


class StyleVelocityGenerator(Generator):
    """Velocity command for the legs, the style's upper-body posture for waist and arms."""

    def __init__(self, style: UpperBodyStyle):
        self.style = style
        self.ref = KinematicReference(q_rad=g1.DEFAULT_Q_RAD.copy(), style=style.name)

    def update(self, command: Command, state: RobotState) -> KinematicReference:
        self.ref.t_s = state.t_s
        self.ref.root_linvel_b_mps[:2] = (command.vx_mps, command.vy_mps)
        self.ref.root_angvel_b_radps[2] = command.wz_radps
        self.ref.q_rad[:] = self.style.pose(state.t_s)
        return self.ref


class OverrideRetargeter(CopyRetargeter):
    """Copies the reference and asks the tracker to take waist/arm targets from it."""

    def __init__(self, override: bool = True):
        super().__init__()
        self.override = override

    def solve(self, reference: KinematicReference, q_prev: np.ndarray) -> JointReference:
        out = super().solve(reference, q_prev)
        out.upper_body_override = self.override
        return out


def record_rollout(style: UpperBodyStyle, config: RolloutConfig) -> tuple[MotionClip | None, dict]:
    """One rollout; returns (clip at config.fps or None if it fell at once, info)."""
    from g1_control.loop.control_loop import ControlLoop
    from g1_control.sim.mujoco_backend import MujocoBackend
    from g1_control.trackers.locomotion import LocomotionPolicyTracker
    from g1_control.trackers.policy_spec import load_spec

    segments = random_commands(config)
    box: list[ControlLoop] = []
    loop = ControlLoop(MujocoBackend(), _TimelineInput(segments, lambda: box[0].time_s if box else 0.0),
                       StyleVelocityGenerator(style), OverrideRetargeter(style.override),
                       LocomotionPolicyTracker(load_spec("holosoma_loco_ppo")),
                       log_capacity=int(config.duration_s * 50) + 10)
    box.append(loop)
    loop.reset()
    # Run in 1 s pieces so that a fall stops the recording early.
    for _ in range(int(np.ceil(config.duration_s))):
        loop.run(1.0)
        if loop.faulted:
            break
    log = loop.log.arrays()
    loop.backend.close()
    valid = ~np.isnan(log["base_pos_m"][:, 0])
    if loop.faulted:
        # Damped frames are not motion anyone commanded; before a fall, the last 2 s were
        # already a loss of balance.
        valid &= log["t_s"] < loop.safety.trip_event.t_s - (2.0 if loop.fell else 0.0)
    n = int(np.argmin(valid)) if not valid.all() else len(valid)
    info = {"style": style.name, "seed": config.seed, "fell": bool(loop.fell),
            "fault": loop.safety.trip_event.kind.value if loop.faulted else None, "recorded_s": float(n / 50.0),
            "commands": segments}
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
