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
        getattr(loop.input, "name", type(loop.input).__name__),
        f"{tick['p99_us'] / 1000:.2f} ms / {loop.scheduler.deadline_misses}",
    ])
    return labels, values
