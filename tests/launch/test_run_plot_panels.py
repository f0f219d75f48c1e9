"""The run plot draws what it promises (the old test checked only the file size): three velocity
panels with commanded, corrected, achieved and estimated lines, and the pelvis height panel."""

from __future__ import annotations

import numpy as np

from g1_control.launch import plots
from g1_control.launch.runner import RunResult, SegmentResult


def test_run_plot_panels_and_lines(tmp_path, monkeypatch):
    import matplotlib.figure

    figures = []
    real_savefig = matplotlib.figure.Figure.savefig

    def capture(self, *args, **kwargs):
        figures.append(self)
        return real_savefig(self, *args, **kwargs)

    monkeypatch.setattr(matplotlib.figure.Figure, "savefig", capture)
    n = 100
    t = np.arange(n) * 0.02
    log = {"t_s": t, "command": np.tile([0.5, 0.0, 0.2], (n, 1)), "policy_command": np.tile([0.55, 0.0, 0.2], (n, 1)),
           "velocity_true": np.tile([0.48, 0.01, 0.19], (n, 1)), "velocity_est": np.tile([0.47, 0.0, 0.2], (n, 1)),
           "base_pos_m": np.column_stack([t, np.zeros(n), np.full(n, 0.74)])}
    result = RunResult(name="t", fell=False, duration_s=2.0, wall_s=1.0,
                       segments=[SegmentResult("walk", 0.0, 2.0, (0.5, 0.0, 0.2), (0.48, 0.01, 0.19))],
                       timings={}, deadline_misses=0, overruns=0, events=[], estimator_rms_mps=None)
    plots.plot_run(log, result, tmp_path / "velocity.png")
    (fig,) = figures
    axes = fig.axes
    assert [a.get_ylabel() for a in axes] == ["forward vx (m/s)", "lateral vy (m/s)", "yaw rate wz (rad/s)",
                                              "pelvis height (m)"]
    for k, ax in enumerate(axes[:3]):
        ys = {line.get_label(): line.get_ydata() for line in ax.get_lines() if not line.get_label().startswith("_")}
        np.testing.assert_allclose(ys["commanded"], log["command"][:, k])
        np.testing.assert_allclose(ys["to policy (corrected)"], log["policy_command"][:, k])
        np.testing.assert_allclose(ys["achieved (ground truth)"], log["velocity_true"][:, k])
        np.testing.assert_allclose(ys["estimated"], log["velocity_est"][:, k])
    height = [line for line in axes[3].get_lines() if len(line.get_ydata()) == n]
    np.testing.assert_allclose(height[0].get_ydata(), 0.74)
    assert "no fall" in fig._suptitle.get_text()
