"""g1 bench odometry's drift attribution (tools/bench_odometry.py) on synthetic runs whose drift is
known: error growing 2 cm per metre walked and 5 cm per 90 deg turned is found as such."""

from __future__ import annotations

import math

import numpy as np
import pytest

from g1_control.tools.bench_odometry import fit_drift, segment_growth, walked_and_turned


def _run() -> dict:
    """Walk 4 m along x (0.5 m/s), turn 180 deg in place (0.5 rad/s), walk 2 m along -x; the estimate's
    error grows along y by 2 cm per metre walked and 5 cm per 90 deg turned."""
    dt = 0.02
    t, x, yaw, err = [0.0], [0.0], [0.0], [0.0]
    ends = []
    for seconds, v, w in ((8.0, 0.5, 0.0), (2 * math.pi, 0.0, 0.5), (4.0, -0.5, 0.0)):
        for _ in range(round(seconds / dt)):
            t.append(t[-1] + dt)
            x.append(x[-1] + v * dt)
            yaw.append(yaw[-1] + w * dt)
            err.append(err[-1] + 0.02 * abs(v) * dt + 0.05 * abs(w) * dt / (math.pi / 2))
        ends.append(t[-1])
    truth = np.column_stack([x, np.zeros(len(x))])
    estimate = truth + np.column_stack([np.zeros(len(x)), err])
    return {"t_s": np.array(t), "truth": truth, "yaw": np.array(yaw), "legs": estimate, "segment_ends_s": ends}


def test_known_drift_is_attributed_to_walking_and_turning():
    run = _run()
    walked, turned = walked_and_turned(run)
    assert walked[-1] == pytest.approx(6.0, abs=0.05) and math.degrees(turned[-1]) == pytest.approx(180, abs=2)
    samples = segment_growth(run, "legs")
    assert len(samples) == 3
    per_m, per_90 = fit_drift(samples)
    assert per_m == pytest.approx(0.02, abs=0.002) and per_90 == pytest.approx(0.05, abs=0.005)
