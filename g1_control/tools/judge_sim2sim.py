"""Judge a deploy's goals against the robot emulator's ground truth: `g1 deploy FILE --json REPORT`
against `g1 sim-robot --record TRUTH.npz` (the robot code never saw that truth).

    python -m g1_control.tools.judge_sim2sim REPORT.json TRUTH.npz        # one line per goal
    python -m g1_control.tools.judge_sim2sim REPORT.json TRUTH.npz --json # the figures as JSON

Each goal the deploy started is judged by report/outcomes.py judge_goal from the execution layer's
record of it (its times in the host's monotonic clock, its target in the scene) and the recorded hand
points, soles and boxes: a reach by the hand's distance from its point over the hold, a pick by the
box's rise and slip, a place by where the box ended up, a step by where the soles were. Goals that
never started are listed as the deploy reported them.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

from g1_control.report.outcomes import judge_goal, outcome_line


def judge(report: dict, truth: dict[str, np.ndarray]) -> list[dict]:
    """The deploy report's goals judged against the emulator's recorded ground truth."""
    out = []
    for goal in report.get("goals", []):
        record = goal.get("record")
        if record is None:  # never started: nothing happened to judge
            out.append(goal)
            continue
        out.append(dict(judge_goal(goal["goal_id"], record, truth), message=goal.get("message")))
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m g1_control.tools.judge_sim2sim", description=__doc__.split("\n\n")[0])
    parser.add_argument("report", type=Path, help="the deploy's --json report (or its run folder's summary.json)")
    parser.add_argument("truth", type=Path, help="g1 sim-robot --record's .npz")
    parser.add_argument("--json", action="store_true", help="print the figures as one JSON list")
    args = parser.parse_args(argv)
    with np.load(args.truth) as npz:
        truth = {k: npz[k] for k in npz.files}
    goals = judge(json.loads(args.report.read_text()), truth)
    if args.json:
        print(json.dumps(goals))
    else:
        for goal in goals:
            print(outcome_line(goal))
    return 0


if __name__ == "__main__":
    sys.exit(main())
