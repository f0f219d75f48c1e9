"""Scripted command timelines: an InputDevice that plays segments against a clock."""

from __future__ import annotations

import bisect
from collections.abc import Callable, Sequence

import numpy as np

from g1_control.interfaces import InputDevice
from g1_control.launch.schema import RandomTimelineConfig, Segment
from g1_control.types import Command


class ScriptedInput(InputDevice):
    """Plays `segments` back to back; after the last one, commands zero velocity."""

    def __init__(self, segments: Sequence[Segment], clock: Callable[[], float]):
        if not segments:
            raise ValueError("a scripted timeline needs at least one segment")
        self.segments = list(segments)
        self.clock = clock
        self.starts = np.concatenate([[0.0], np.cumsum([s.duration_s for s in self.segments])])
        self._commands = [
            Command(vx_mps=s.vx_mps, vy_mps=s.vy_mps, wz_radps=s.wz_radps, style=s.style).validate()
            for s in self.segments
        ] + [Command()]

    @property
    def duration_s(self) -> float:
        return float(self.starts[-1])

    def index_at(self, t_s: float) -> int:
        """Segment index playing at `t_s` (len(segments) after the end)."""
        return min(bisect.bisect_right(self.starts, t_s) - 1, len(self.segments))

    def poll(self) -> Command:
        return self._commands[self.index_at(self.clock())]


def random_timeline(config: RandomTimelineConfig, duration_s: float) -> list[Segment]:
    """Seeded random segments: stands, walks, turns, sidesteps and their mixes; starts standing."""
    rng = np.random.default_rng(config.seed)
    segments = [Segment(duration_s=2.0, label="stand")]
    total = 2.0
    while total < duration_s:
        length = min(float(rng.uniform(*config.segment_s)), duration_s - total)
        if rng.random() < config.stand_probability:
            seg = Segment(duration_s=length, label="stand")
        else:
            vx, vy, wz = (float(rng.uniform(*r)) for r in (config.vx_mps, config.vy_mps, config.wz_radps))
            # Mostly one dominant motion, as an operator would command.
            keep = rng.choice(3, p=[0.5, 0.2, 0.3])
            mix = rng.random() < 0.3
            vx, vy, wz = [(v if (i == keep or mix) else 0.0) for i, v in enumerate((vx, vy, wz))]
            seg = Segment(duration_s=length, vx_mps=round(vx, 3), vy_mps=round(vy, 3), wz_radps=round(wz, 3),
                          label="random")
        segments.append(seg)
        total += length
    return segments
