"""Verdict: whether something the robot did met its goal, judged from ground truth, with the
figures it was judged on. One class for every judge: a program step (program/judge.py) and a
trial of `g1 bench execution` (tools/bench_execution.py, tools/execution_goals.py)."""

from __future__ import annotations

from dataclasses import dataclass, field


@dataclass
class Verdict:
    ok: bool
    """Met its goal."""
    text: str = ""
    """What was measured against what was asked, for people ('turned 88.9 deg of 90 (-1.1 deg)')."""
    values: dict[str, float] = field(default_factory=dict)
    """The figures by name, with units in the name (`hand_error_m`, `velocity_error_pct`)."""
    count: int = 1
    """How many goals it judged (a sequence of reaches, of heights); 1 for one goal."""
    successes: int | None = None
    """Of those, how many met theirs (None: `ok` says it for the one goal)."""

    def met(self) -> int:
        """How many of its `count` goals were met."""
        return int(self.ok) if self.successes is None else self.successes


def figures(**named: float | None) -> dict[str, float]:
    """Verdict.values from keyword figures, leaving out the ones not measured (None)."""
    return {name: float(value) for name, value in named.items() if value is not None}


__all__ = ["Verdict", "figures"]
