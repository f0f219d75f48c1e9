"""The on-screen overlay of the MuJoCo viewer: command, style, safety state, timing."""

from __future__ import annotations

from g1_control.loop.control_loop import ControlLoop


def overlay_lines(loop: ControlLoop) -> tuple[str, str]:
    """(labels, values) columns for the viewer's top-left text block."""
    c = loop.command
    trip = loop.safety.trip_event
    if trip is not None:  # i.e. loop.safety.tripped
        state = f"DAMPING ({trip.kind.value})"
    elif loop.input.lost:
        state = "INPUT LOST: stopping"
    else:
        state = "ok"
    est = loop.estimator.estimate.heading_velocity
    tick = loop.scheduler.tick_times.summary()
    labels = "time\ncommand vx vy wz\nachieved vx vy wz\nstyle\nsafety\ninput\ntick p99 / misses"
    values = "\n".join([
        f"{loop.time_s:7.1f} s",
        f"{c.vx_mps:+.2f} {c.vy_mps:+.2f} {c.wz_radps:+.2f}",
        f"{est[0]:+.2f} {est[1]:+.2f} {est[2]:+.2f}",
        c.style,
        state,
        loop.input.describe(),
        f"{tick['p99_us'] / 1000:.2f} ms / {loop.scheduler.deadline_misses}",
    ])
    return labels, values


WARNING_SHOWN_S = 2.0
"""How long a safety event that does not trip stays in a recorded run's overlay."""


def safety_state_at(t_s: float, events: list[dict]) -> str:
    """The safety state at `t_s` from a run's events (summary.json): DAMPING once a tripping event
    happened (its `trips` flag), a recent warning, else ok."""
    state = "ok"
    for e in events:
        if e["t_s"] > t_s:
            break
        if e.get("trips"):
            return f"DAMPING ({e['kind']})"
        if t_s - e["t_s"] <= WARNING_SHOWN_S:
            state = f"warning: {e['kind']}"
    return state


def run_overlay_rows(log: dict, events: list[dict], segments: list[dict] | None = None) -> list[str]:
    """One overlay text per log row of a recorded run: time and segment, the command, the achieved
    velocity (ground truth, or the estimate on a robot, averaged over one gait cycle) and the safety state."""
    import numpy as np

    from g1_control.report.plots import window_mean

    t = log["t_s"]
    truth = log["velocity_true"]
    source = "truth" if not np.isnan(truth).all() else "estimate"
    achieved = window_mean(t, truth if source == "truth" else log["velocity_est"])
    events = sorted(events or [], key=lambda e: e["t_s"])
    rows = []
    for i, now in enumerate(t):
        seg = next((s["label"] for s in segments or () if s["start_s"] <= now < s["end_s"]), "")
        c, a = log["command"][i], achieved[i]
        rows.append("\n".join([
            f"t {now:6.1f} s" + (f"   {seg}" if seg else ""),
            f"command   vx {c[0]:+.2f}  vy {c[1]:+.2f}  wz {c[2]:+.2f}",
            f"achieved  vx {a[0]:+.2f}  vy {a[1]:+.2f}  wz {a[2]:+.2f}  ({source}, 1 s mean)",
            f"safety    {safety_state_at(float(now), events)}",
        ]))
    return rows
