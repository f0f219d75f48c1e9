"""Scripted command timelines: an InputDevice that plays segments against a clock."""

from __future__ import annotations

import bisect
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Literal

import numpy as np

from g1_control.errors import LaunchFileError
from g1_control.interfaces import InputDevice
from g1_control.types import Command, TaskGoal


@dataclass
class GoalEntry:
    """A goal in a timeline segment (g1_control.types.TaskGoal, as a launch file writes it)."""

    kind: Literal["reach", "pick", "place", "step_up", "step_down"]
    hand: Literal["left", "right", "both"] = "right"
    object: str | None = None
    """pick / place: a box or bottle of the scene (none: the nearest box in front / the one held)."""
    target: str | None = None
    """place: a table or platform of the scene; step_up: a platform (none: the nearest in front)."""
    pos_w_m: tuple[float, float, float] | None = None
    """reach: the point (world); place: where the box's centre goes (xy; z from the surface)."""
    offset_h_m: tuple[float, float, float] | None = None
    """reach: the hand's standing position moved by this (x forward, y left, z up)."""

    def validate(self, where: str) -> None:
        if self.kind == "reach" and (self.pos_w_m is None) == (self.offset_h_m is None):
            raise LaunchFileError(f"{where}: a reach goal needs pos_w_m or offset_h_m (one of them)")
        if self.kind != "reach" and self.offset_h_m is not None:
            raise LaunchFileError(f"{where}.offset_h_m: only a reach goal takes an offset")
        if self.kind in ("step_up", "step_down", "pick") and self.pos_w_m is not None:
            raise LaunchFileError(f"{where}.pos_w_m: a {self.kind} goal takes no point (name the "
                                  f"{'object' if self.kind == 'pick' else 'target'} instead)")
        if self.kind == "pick" and self.target is not None:
            raise LaunchFileError(f"{where}.target: a pick goal names its box with `object`")

    def to_goal(self, goal_id: str) -> TaskGoal:
        return TaskGoal(self.kind, goal_id, self.hand, self.object, self.target,
                        None if self.pos_w_m is None else np.asarray(self.pos_w_m, dtype=float),
                        None if self.offset_h_m is None else np.asarray(self.offset_h_m, dtype=float))


@dataclass
class Segment:
    """One piece of a scripted command timeline."""

    duration_s: float
    vx_mps: float = 0.0
    vy_mps: float = 0.0
    wz_radps: float = 0.0
    label: str = ""
    style: str = "default"
    pelvis_height_m: float | None = None
    """A pelvis height to hold (m above the ground); None: the tracker's own."""
    goals: list[GoalEntry] = field(default_factory=list)
    """Goals started when the segment starts (they run to their end, past the segment's if need be;
    the next ones queue behind them). Their ids are 'seg<i>.<j>'."""

    def validate(self, where: str) -> None:
        if self.duration_s <= 0:
            raise LaunchFileError(f"{where}.duration_s: must be > 0, got {self.duration_s}")
        if self.pelvis_height_m is not None and not 0.3 <= self.pelvis_height_m <= 1.0:
            raise LaunchFileError(f"{where}.pelvis_height_m: {self.pelvis_height_m} m is outside [0.3, 1.0] m")


@dataclass
class RandomTimelineConfig:
    seed: int = 0
    segment_s: tuple[float, float] = (3.0, 8.0)
    vx_mps: tuple[float, float] = (-0.4, 0.8)
    vy_mps: tuple[float, float] = (-0.3, 0.3)
    wz_radps: tuple[float, float] = (-0.6, 0.6)
    stand_probability: float = 0.2
    style: str = "default"
    """Upper-body style of every segment."""


def segment_goal_id(segment: int, goal: int) -> str:
    """The goal_id ScriptedInput gives goal `goal` of timeline segment `segment`."""
    return f"seg{segment}.{goal}"


def timeline_goals(segments: Sequence[Segment]) -> list[TaskGoal]:
    """Every task goal of a timeline, in order, with the goal_ids ScriptedInput gives them."""
    return [g.to_goal(segment_goal_id(i, j)) for i, s in enumerate(segments) for j, g in enumerate(s.goals)]


class ScriptedInput(InputDevice):
    """Plays `segments` back to back from `start_s` on the poll's clock; after the last one (and
    before `start_s`), commands zero velocity."""

    def __init__(self, segments: Sequence[Segment], start_s: float = 0.0):
        if not segments:
            raise ValueError("a scripted timeline needs at least one segment")
        self.segments = list(segments)
        self.start_s = start_s
        self.starts = np.concatenate([[0.0], np.cumsum([s.duration_s for s in self.segments])])
        self._commands = [
            Command(vx_mps=s.vx_mps, vy_mps=s.vy_mps, wz_radps=s.wz_radps, style=s.style,
                    pelvis_height_m=s.pelvis_height_m,
                    tasks=[g.to_goal(segment_goal_id(i, j)) for j, g in enumerate(s.goals)]).validate()
            for i, s in enumerate(self.segments)
        ] + [Command()]

    @property
    def duration_s(self) -> float:
        return float(self.starts[-1])

    def index_at(self, t_s: float) -> int:
        """Segment index playing at `t_s` (len(segments) after the end)."""
        return min(bisect.bisect_right(self.starts, t_s) - 1, len(self.segments))

    def poll(self, now_s: float) -> Command:
        t = now_s - self.start_s
        return self._commands[self.index_at(t)] if t >= 0.0 else self._commands[-1]


def random_timeline(config: RandomTimelineConfig, duration_s: float) -> list[Segment]:
    """Seeded random segments: stands, walks, turns, sidesteps and their mixes; starts standing."""
    rng = np.random.default_rng(config.seed)
    segments = [Segment(duration_s=2.0, label="stand", style=config.style)]
    total = 2.0
    while total < duration_s:
        length = min(float(rng.uniform(*config.segment_s)), duration_s - total)
        if rng.random() < config.stand_probability:
            seg = Segment(duration_s=length, label="stand", style=config.style)
        else:
            vx, vy, wz = (float(rng.uniform(*r)) for r in (config.vx_mps, config.vy_mps, config.wz_radps))
            # Mostly one dominant motion, as an operator would command.
            keep = rng.choice(3, p=[0.5, 0.2, 0.3])
            mix = rng.random() < 0.3
            vx, vy, wz = [(v if (i == keep or mix) else 0.0) for i, v in enumerate((vx, vy, wz))]
            seg = Segment(duration_s=length, vx_mps=round(vx, 3), vy_mps=round(vy, 3), wz_radps=round(wz, 3),
                          label="random", style=config.style)
        segments.append(seg)
        total += length
    return segments
