"""The run plot (velocity.png): commanded vs achieved velocity per axis and pelvis height over time.

A walking policy's base velocity swings within every step, so the raw 50 Hz trace hides the
speed it actually makes good. The plot therefore shows each velocity averaged over one gait
cycle (a centred 1 s window: the holosoma policies' gait period is 1.0 s, see
g1_control/policies/specs/holosoma_loco_ppo.yaml), with the raw ground truth faint behind it.
Segments of the command timeline are shaded and labelled; the legend sits above the panels,
outside the data.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

GAIT_WINDOW_S = 1.0
"""Averaging window: one gait cycle of the walking policies."""


def window_mean(t: np.ndarray, x: np.ndarray, window_s: float = GAIT_WINDOW_S) -> np.ndarray:
    """Centred moving mean of `x` (rows at times `t`) over `window_s`, ignoring NaN samples.

    Near the ends the window is cut short; where a window holds no finite sample the mean is NaN.
    """
    x = np.asarray(x, dtype=float)
    n_rows = len(t)
    if n_rows == 0:
        return x.copy()
    flat = x.reshape(n_rows, -1)
    dt = float(np.median(np.diff(t))) if n_rows > 1 else 1.0
    n = max(1, round(window_s / dt)) if dt > 0 else 1
    valid = np.isfinite(flat)
    csum = np.vstack([np.zeros((1, flat.shape[1])), np.cumsum(np.where(valid, flat, 0.0), axis=0)])
    ccount = np.vstack([np.zeros((1, flat.shape[1])), np.cumsum(valid, axis=0)])
    rows = np.arange(n_rows)
    lo = np.clip(rows - n // 2, 0, n_rows)
    hi = np.clip(rows - n // 2 + n, 0, n_rows)
    count = ccount[hi] - ccount[lo]
    with np.errstate(invalid="ignore", divide="ignore"):
        mean = np.where(count > 0, (csum[hi] - csum[lo]) / np.maximum(count, 1), np.nan)
    return mean.reshape(x.shape)


def plot_run(log: dict[str, np.ndarray], result, out: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    t = log["t_s"]
    truth = window_mean(t, log["velocity_true"])
    est = window_mean(t, log["velocity_est"])
    fig, axes = plt.subplots(4, 1, figsize=(12, 10), sharex=True, height_ratios=(1, 1, 1, 0.7))
    labels = ("forward vx (m/s)", "lateral vy (m/s)", "yaw rate wz (rad/s)")
    for k, ax in enumerate(axes[:3]):
        ax.plot(t, log["velocity_true"][:, k], color="tab:blue", lw=0.6, alpha=0.25, zorder=2)
        ax.plot(t, log["policy_command"][:, k], color="0.55", lw=0.9, ls=":", zorder=3)
        ax.plot(t, truth[:, k], color="tab:blue", lw=2.2, zorder=4)
        ax.plot(t, est[:, k], color="tab:orange", lw=1.0, zorder=5)  # thin, on top: the truth shows around it
        ax.plot(t, log["command"][:, k], color="k", lw=1.3, ls="--", zorder=6)
        ax.set_ylabel(labels[k])
        ax.grid(alpha=0.3)
    axes[3].plot(t, log["base_pos_m"][:, 2], color="tab:green")
    axes[3].set_ylabel("pelvis height (m)")
    axes[3].set_xlabel("time (s)")
    axes[3].grid(alpha=0.3)

    for i, seg in enumerate(result.segments):
        for ax in axes:
            if i % 2 == 0:
                ax.axvspan(seg.start_s, seg.end_s, color="0.93", lw=0, zorder=0)
            ax.axvline(seg.start_s, color="0.75", lw=0.6, zorder=1)
        axes[0].text((seg.start_s + seg.end_s) / 2, 1.02, seg.label, transform=axes[0].get_xaxis_transform(),
                     ha="center", va="bottom", fontsize=8, clip_on=False,
                     rotation=0 if seg.end_s - seg.start_s >= 4.5 else 30)
    trip = next((e for e in result.events if e.get("trips")), None)
    if trip is not None:
        for ax in axes:
            ax.axvline(trip["t_s"], color="tab:red", lw=1.2, zorder=7)
        axes[3].annotate(f"safety: {trip['kind']} (damping)", (trip["t_s"], 0.05), xycoords=("data", "axes fraction"),
                         color="tab:red", fontsize=8, xytext=(4, 0), textcoords="offset points")

    handles = [
        Line2D([], [], color="k", lw=1.3, ls="--", label="commanded"),
        Line2D([], [], color="tab:blue", lw=2.2, label=f"achieved, ground truth ({GAIT_WINDOW_S:g} s gait-cycle mean)"),
        Line2D([], [], color="tab:blue", lw=0.8, alpha=0.35, label="achieved, ground truth (raw 50 Hz)"),
        Line2D([], [], color="tab:orange", lw=1.0, label=f"state estimate ({GAIT_WINDOW_S:g} s mean)"),
        Line2D([], [], color="0.55", lw=0.9, ls=":", label="sent to the policy (after velocity correction)"),
        Patch(facecolor="0.93", edgecolor="0.75", label="command segments"),
    ]
    status = "no fall" if result.fall is None else f"FELL at {result.fall['t_s']:.1f} s"
    fig.suptitle(f"{result.name}: {status}, real-time factor {result.real_time_factor:.1f}x", y=0.995)
    fig.legend(handles=handles, loc="upper center", ncol=3, fontsize=8, frameon=False, bbox_to_anchor=(0.5, 0.97))
    fig.tight_layout(rect=(0, 0, 1, 0.925))
    fig.savefig(out, dpi=90)
    plt.close(fig)
