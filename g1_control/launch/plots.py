"""The run plot: commanded vs achieved velocity per axis and pelvis height over time."""

from __future__ import annotations

from pathlib import Path

import numpy as np


def plot_run(log: dict[str, np.ndarray], result, out: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    t = log["t_s"]
    fig, axes = plt.subplots(4, 1, figsize=(10, 9), sharex=True)
    labels = ("forward vx (m/s)", "lateral vy (m/s)", "yaw rate wz (rad/s)")
    for k, ax in enumerate(axes[:3]):
        ax.plot(t, log["command"][:, k], "k--", lw=1.2, label="commanded")
        ax.plot(t, log["policy_command"][:, k], color="0.6", lw=0.8, label="to policy (corrected)")
        ax.plot(t, log["velocity_true"][:, k], color="tab:blue", lw=0.8, label="achieved (ground truth)")
        ax.plot(t, log["velocity_est"][:, k], color="tab:orange", lw=0.8, alpha=0.8, label="estimated")
        ax.set_ylabel(labels[k])
        ax.grid(alpha=0.3)
    axes[0].legend(loc="upper right", fontsize=8, ncol=4)
    axes[3].plot(t, log["base_pos_m"][:, 2], color="tab:green")
    axes[3].set_ylabel("pelvis height (m)")
    axes[3].set_xlabel("time (s)")
    axes[3].grid(alpha=0.3)
    for seg in result.segments:
        for ax in axes:
            ax.axvline(seg.start_s, color="0.85", lw=0.8, zorder=0)
    status = "no fall" if result.fall is None else f"FELL at {result.fall['t_s']:.1f} s"
    fig.suptitle(f"{result.name}: {status}, real-time factor {result.real_time_factor:.1f}x")
    fig.tight_layout()
    fig.savefig(out, dpi=90)
    plt.close(fig)
