"""The loop thread imports nothing on the first whole-body plan of a run: once the goal executor is
built, making a plan's trajectory (WholeBodyTrajectory, in the loop thread at every hand-over to the
whole-body controller) loads no module. Measured over DDS: a lazy `from scipy.interpolate import
CubicSpline` there stalled the deploy's loop 220 ms at its first hand-over (10 deadline overruns: a
trip) whenever the preflight's dry run, in the same process, had not made a whole-body plan first (a
step onto a platform that only perception reports)."""

from __future__ import annotations

import subprocess
import sys

from tests.paths import REPO

PROBE = """
import sys
import numpy as np
import g1_control.generator.goals.executor  # what the launch builder imports for a goal executor
from g1_control.generator.whole_body import keyframe_trajectory
from g1_control.robot import g1

q = np.concatenate([[0.0, 0.0, 0.79, 0.0, 0.0, 0.0, 1.0], g1.DEFAULT_Q_RAD])
before = set(sys.modules)
keyframe_trajectory("stand", [(0.0, q), (1.0, q)]).sample(0.5)
print(sorted(set(sys.modules) - before))
"""


def test_the_first_whole_body_trajectory_of_a_run_imports_nothing():
    out = subprocess.run([sys.executable, "-c", PROBE], check=False, cwd=REPO, capture_output=True, text=True,
                         timeout=300, env={"PYTHONPATH": str(REPO), "PATH": "/usr/bin:/bin"})
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "[]"
