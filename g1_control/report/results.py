"""A run's figures, read from its log: velocity per command segment (steady state), the upper
body vs the tracker's reference, stage timings, falls and events; the run's summary (summary.json)
and its printed report. `g1 launch`, `g1 say`, `g1 deploy`, the library's rollouts and the benches
read runs through here (launch/runner.py runs them; run_folder.py writes them)."""

from __future__ import annotations

import dataclasses
import itertools
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from g1_control.robot import g1
from g1_control.teleop.scripted import Segment

if TYPE_CHECKING:
    from g1_control.loop.control_loop import ControlLoop

STEADY_STATE_SKIP_S = 2.0
"""Time after a segment starts before its velocity counts as steady state."""
UPPER_BODY = list(g1.UPPER_BODY_JOINTS)



@dataclass
class SegmentResult:
    label: str
    start_s: float
    end_s: float
    commanded: tuple[float, float, float]
    achieved: tuple[float, float, float]
    upper_body_rms_rad: float | None = None
    """Waist and arm joints, measured vs the tracker's reference posture (the plan after the IK),
    RMS over the same steady-state window; None without a reference."""

    def error_pct(self) -> tuple[float | None, float | None, float | None]:
        """Relative error per axis where the command is meaningfully non-zero."""

        def pct(c: float, a: float) -> float | None:
            return (100.0 * (a - c) / c) if abs(c) >= 0.1 else None

        (c0, c1, c2), (a0, a1, a2) = self.commanded, self.achieved
        return pct(c0, a0), pct(c1, a1), pct(c2, a2)


@dataclass
class RunResult:
    name: str
    fell: bool
    duration_s: float
    wall_s: float
    segments: list[SegmentResult]
    timings: dict[str, dict[str, float]]
    deadline_misses: int
    overruns: int
    events: list[dict]
    estimator_rms_mps: float | None
    chain: dict[str, str] = field(default_factory=dict)
    """What each stage of the loop was (g1_control/launch/builder.py)."""
    run_dir: Path | None = None
    video: str | None = None
    extra: dict = field(default_factory=dict)
    fall: dict | None = None
    """The first fall (g1_control/safety/fall.py): {t_s, kind, detail}; None when the robot stayed up."""

    @property
    def real_time_factor(self) -> float:
        return self.duration_s / self.wall_s if self.wall_s > 0 else float("inf")


def segments_from_log(log: dict[str, np.ndarray], min_s: float = 1.0) -> list[tuple[float, Segment]]:
    """Stretches of constant operator command in a log (for live or device-driven runs)."""
    t, cmd = log["t_s"], log["command"]
    if len(t) == 0:
        return []
    change = np.nonzero(np.any(np.abs(np.diff(cmd, axis=0)) > 1e-6, axis=1))[0] + 1
    bounds = np.concatenate([[0], change, [len(t)]])
    dt = t[1] - t[0] if len(t) > 1 else 0.02
    out = []
    for a, b in itertools.pairwise(bounds):
        if (b - a) * dt >= min_s:
            vx, vy, wz = (float(v) for v in cmd[a])
            out.append((float(t[a]), Segment(duration_s=float((b - a) * dt), vx_mps=vx, vy_mps=vy, wz_radps=wz,
                                            label="held")))
    return out


def upper_body_rms(log: dict[str, np.ndarray], rows: np.ndarray) -> float | None:
    """Waist and arm joints as measured vs the tracker's reference posture (the plan after the IK):
    RMS (rad) over the ticks `rows` that have a reference; None when none has."""
    rows = rows & ~np.isnan(log["q_ref_rad"][:, 0])
    if not rows.any():
        return None
    err = log["q_rad"][rows][:, UPPER_BODY] - log["q_ref_rad"][rows][:, UPPER_BODY]
    return float(np.sqrt(np.mean(err**2)))


def upper_body_rms_by_style(log: dict[str, np.ndarray], window: np.ndarray | None = None,
                            settle_s: float = 1.0) -> dict[str, dict[str, float]]:
    """Waist and arm joints as measured vs the tracker's reference posture (the plan after the IK),
    per operator style: RMS (rad) over the ticks in `window`, skipping the first `settle_s` after each
    style change (the arms are still moving to the new pose)."""
    ids, t = log["style_id"], log["t_s"]
    if window is None:
        window = np.ones(len(t), dtype=bool)
    change_t = np.full(len(t), -np.inf)
    last = -np.inf
    for k in range(len(t)):
        if k == 0 or ids[k] != ids[k - 1]:
            last = t[k]
        change_t[k] = last
    settled = window & (t - change_t >= settle_s) & ~np.isnan(log["q_ref_rad"][:, 0])
    out = {}
    for i, name in enumerate(log["style_names"]):
        rows = settled & (ids == i)
        rms = upper_body_rms(log, rows)
        if rows.sum() < 5 or rms is None:
            continue
        out[str(name)] = {"rms_rad": rms, "seconds": float(rows.sum() * np.median(np.diff(t)))}
    return out


def segment_results(log: dict[str, np.ndarray], segments: list[Segment]) -> list[SegmentResult]:
    t = log["t_s"]
    achieved = log["velocity_true"] if not np.isnan(log["velocity_true"]).all() else log["velocity_est"]
    if segments:
        starts = np.concatenate([[0.0], np.cumsum([s.duration_s for s in segments])[:-1]])
        timed = list(zip(starts, segments))
    else:
        timed = segments_from_log(log)
    out = []
    for start, seg in timed:
        end = start + seg.duration_s
        window = (t >= start + min(STEADY_STATE_SKIP_S, seg.duration_s / 2)) & (t < end)
        mean = achieved[window].mean(axis=0) if window.any() else np.full(3, np.nan)
        ub = upper_body_rms(log, window)
        out.append(SegmentResult(seg.label or "segment", start, end, (seg.vx_mps, seg.vy_mps, seg.wz_radps),
                                 (float(mean[0]), float(mean[1]), float(mean[2])), ub))
    return out


def run_result(name: str, loop: ControlLoop, segments: list[Segment], wall: float,
               log: dict[str, np.ndarray]) -> RunResult:
    """The RunResult of a finished loop (`wall`: the run's wall seconds) from its log."""
    est_rms = None
    valid = ~np.isnan(log["velocity_true"][:, 0])
    if valid.sum() > 10:
        err = log["velocity_est"][valid, :2] - log["velocity_true"][valid, :2]
        est_rms = float(np.sqrt((err**2).sum(axis=1).mean()))
    fall = loop.fall
    return RunResult(
        name=name, fell=fall is not None, fall=dataclasses.asdict(fall) if fall else None,
        duration_s=loop.time_s, wall_s=wall,
        segments=segment_results(log, segments), timings=loop.scheduler.report(),
        deadline_misses=loop.scheduler.deadline_misses, overruns=loop.scheduler.overruns,
        events=[dataclasses.asdict(e) for e in loop.events], estimator_rms_mps=est_rms, chain=dict(loop.chain),
    )


def summary_dict(result: RunResult) -> dict:
    d = dataclasses.asdict(result)
    d["run_dir"] = str(result.run_dir) if result.run_dir else None
    d["real_time_factor"] = result.real_time_factor
    d["segments"] = [dict(dataclasses.asdict(s), error_pct=s.error_pct()) for s in result.segments]
    return d


def program_summary(program: dict) -> str:
    """The steps of a program run, each with the runner's outcome and the ground-truth verdict."""
    steps = program["steps"]
    judged = [s for s in steps if "verdict" in s]
    ok = sum(s["verdict"]["ok"] for s in judged)
    lines = [f"program (steered by {program['pose']}): {len(steps)} steps ran"
             + ("" if program["finished"] else ", STOPPED before the end")
             + (f"; {ok}/{len(judged)} met by ground truth" if judged else "")]
    for s in steps:
        line = f"  {s['label']}. {s['description']}: {s['status']} after {s['ended_s'] - s['started_s']:.1f} s"
        if "verdict" in s:
            line += f" | {s['verdict']['text']} {'OK' if s['verdict']['ok'] else 'MISSED'}"
        lines.append(line)
    return "\n".join(lines)


def fall_text(fall: dict | None) -> str:
    """'no fall', or 'FELL at 12.34 s: left_knee_link on the ground'."""
    return "no fall" if fall is None else f"FELL at {fall['t_s']:.2f} s: {fall['detail']}"


def format_summary(result: RunResult) -> str:
    lines = [
        (f"run '{result.name}': {fall_text(result.fall)}; {result.duration_s:.1f} s simulated in "
        f"{result.wall_s:.1f} s wall (real-time factor {result.real_time_factor:.1f}x)"),
        "",
        f"{'segment':<12} {'time (s)':>11}   {'commanded vx vy wz':>22}   {'achieved vx vy wz':>22}   "
        f"{'error %':<20} ub rms",
    ]
    for s in result.segments:
        err = " ".join("   -  " if e is None else f"{e:+5.1f}" for e in s.error_pct())
        cmd = " ".join(f"{v:+6.2f}" for v in s.commanded)
        ach = " ".join(f"{v:+6.2f}" for v in s.achieved)
        ub = "-" if s.upper_body_rms_rad is None else f"{s.upper_body_rms_rad:.3f}"
        lines.append(f"{s.label[:12]:<12} {s.start_s:5.1f}-{s.end_s:5.1f}   {cmd:>22}   {ach:>22}   {err:<20} {ub}")
    lines += ["", f"{'stage':<12} {'calls':>7} {'p50 us':>8} {'p99 us':>8} {'max us':>8}"]
    for name, t in result.timings.items():
        lines.append(f"{name:<12} {t['calls']:>7} {t['p50_us']:>8.1f} {t['p99_us']:>8.1f} {t['max_us']:>8.1f}")
    lines.append(f"deadline misses: {result.deadline_misses}; ticks over budget: {result.overruns}")
    if result.estimator_rms_mps is not None:
        lines.append(f"state estimator velocity RMS error vs ground truth: {result.estimator_rms_mps:.3f} m/s")
    for e in result.events:
        lines.append(f"event at {e['t_s']:.2f} s: {e['kind']}{' (damping)' if e.get('trips') else ''}: {e['detail']}")
    if result.extra.get("goals"):
        from g1_control.report.outcomes import outcome_line

        lines += ["", "goals (ground truth):"] + ["  " + outcome_line(o) for o in result.extra["goals"]]
    if result.extra.get("by_style"):
        lines += ["", style_table(result.extra["by_style"])]
    if result.extra.get("pushes"):
        lines += ["", "pushes (ground truth):"] + ["  " + push_line(p) for p in result.extra["pushes"]]
    if result.extra.get("program"):
        lines += ["", program_summary(result.extra["program"])]
    if result.run_dir:
        lines.append(f"run folder: {result.run_dir}" + (f" (video: {Path(result.video).name})" if result.video else ""))
    return "\n".join(lines)


def style_table(by_style: dict[str, dict]) -> str:
    """Per style: the upper body vs the plan, and the footsteps (measured) vs the plan's (report/footsteps.py)."""
    lines = ["per style, vs the plan (after the IK): upper body RMS; footsteps: steps measured/planned/paired, "
             "RMS of the paired steps' difference (x, y), mean step length and width measured (plan)",
             f"{'style':<12} {'ub rms':>7}   {'steps':>11}   {'rms x':>6} {'rms y':>6}   {'length':>13} {'width':>13}"]
    for name, d in by_style.items():
        ub = d.get("upper_body_rms_rad")
        row = f"{name[:12]:<12} {'-' if ub is None else f'{ub:.3f}':>7}"
        f = d.get("footsteps")
        if f:
            counts = f"{f['steps']}/{f['plan_steps']}/{f['paired']}"
            rx, ry = (f"{f[k]:.3f}" if k in f else "-" for k in ("rms_x_m", "rms_y_m"))
            (mx, my), (px, py) = f["mean_step_m"], f["plan_mean_step_m"]
            row += f"   {counts:>11}   {rx:>6} {ry:>6}   {mx:+.2f} ({px:+.2f}) {my:+.2f} ({py:+.2f})"
        lines.append(row)
    return "\n".join(lines)


def push_line(p: dict) -> str:
    """One push's outcome (launch/runner.py push_outcomes) in words."""
    fx, fy, _ = p["force_h_n"]
    text = f"push {p['label'] or ''} at {p['at_s']:.1f} s ({np.hypot(fx, fy):.0f} N for {p['duration_s']:.2f} s, " \
           f"heading frame x {fx:+.0f} y {fy:+.0f}): "
    if p["fell"]:
        return text + "FELL"
    if not p["recovered"]:
        return text + f"not upright again within the window (peak tilt {p.get('peak_tilt_rad', float('nan')):.2f} rad)"
    return text + (f"recovered; peak tilt {p['peak_tilt_rad']:.2f} rad, upright again after {p['upright_after_s']:.1f} s, "
                   f"pelvis moved {p['moved_m']:.2f} m")
