"""What a program run leaves behind: poses, one record per finished step, the ground-truth verdict.

Plain data shared by the program input (device.py), which fills the records, and the judge
(judge.py), which reads them; neither imports the other's code for it.
"""

from __future__ import annotations

from dataclasses import dataclass

from g1_control.program.runner import StepOutcome
from g1_control.program.steps import Step
from g1_control.report.verdict import Verdict


@dataclass(frozen=True)
class PlanarPose:
    x_m: float
    y_m: float
    yaw_rad: float
    pelvis_height_m: float | None = None


@dataclass
class StepRecord:
    """One finished step: the runner's outcome (from the pose it steers by) and, in simulation,
    ground truth at its start and end and the yaw it turned by ground truth."""

    outcome: StepOutcome
    step: Step
    truth_start: PlanarPose | None = None
    truth_end: PlanarPose | None = None
    truth_turned_rad: float | None = None
    goal_id: str | None = None
    message: str | None = None
    """Why the execution layer failed the step's goal (Generator.goal_messages), if it did."""
    verdict: Verdict | None = None
    """Set by the judge (g1_control/program/judge.py) when ground truth exists."""


__all__ = ["PlanarPose", "StepRecord", "Verdict"]
