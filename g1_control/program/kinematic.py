"""A kinematic stand-in for the robot: integrates the runner's commands into a ProgramProgress.

For tests and dry runs (`g1 say --dry-run` can show what a program would do before any physics):
the base moves exactly as commanded, with first-order lags on velocity and yaw rate, and goals
are reported reached (or failed, per kind) a fixed time after they are first requested.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from g1_control.program.runner import GOAL_FAILED, REACHED, ProgramProgress
from g1_control.types import Command


@dataclass
class KinematicProgress:
    x_m: float = 0.0
    y_m: float = 0.0
    yaw_rad: float = 0.0
    lag_s: float = 0.1
    """Time constant of the velocity and yaw-rate response (0: instant)."""
    goal_delay_s: float = 1.0
    goal_results: dict[str, str] = field(default_factory=dict)
    """GoalRequest.kind -> 'reached' / 'failed' / 'never' (default: reached)."""
    _v: tuple[float, float, float] = (0.0, 0.0, 0.0)
    _goal_seen: dict[str, float] = field(default_factory=dict)
    t_s: float = 0.0

    def progress(self, goals=()) -> ProgramProgress:
        """The progress to hand to the runner; `goals` are its active GoalRequests."""
        status = {}
        for g in goals:
            t0 = self._goal_seen.setdefault(g.goal_id, self.t_s)
            result = self.goal_results.get(g.kind, REACHED)
            if self.t_s - t0 >= self.goal_delay_s and result in (REACHED, GOAL_FAILED):
                status[g.goal_id] = result
        return ProgramProgress(self.x_m, self.y_m, self.yaw_rad, status)

    def step(self, cmd: Command, dt_s: float) -> None:
        a = 1.0 if self.lag_s <= 0 else 1.0 - math.exp(-dt_s / self.lag_s)
        vx, vy, wz = (v + a * (c - v) for v, c in zip(self._v, (cmd.vx_mps, cmd.vy_mps, cmd.wz_radps)))
        self._v = (vx, vy, wz)
        c, s = math.cos(self.yaw_rad), math.sin(self.yaw_rad)
        self.x_m += (c * vx - s * vy) * dt_s
        self.y_m += (s * vx + c * vy) * dt_s
        self.yaw_rad = math.remainder(self.yaw_rad + wz * dt_s, math.tau)
        self.t_s += dt_s


def run_kinematic(runner, dt_s: float = 0.02, max_s: float = 600.0, robot: KinematicProgress | None = None):
    """Run a ProgramRunner to its end on a KinematicProgress; returns the robot (its final pose)."""
    robot = robot or KinematicProgress()
    while not runner.done and robot.t_s < max_s:
        cmd = runner.update(robot.t_s, robot.progress(runner.active_goals))
        robot.step(cmd, dt_s)
    return robot
