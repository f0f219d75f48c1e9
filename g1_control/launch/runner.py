"""Build the loop a launch file describes, run it, and write the run folder as it goes
(g1_control/launch/run_folder.py; closed on the end, a fall, SIGINT or SIGTERM):

    runs/<name>-<time>/
      launch.yaml     the validated launch file as run
      log/            per-tracker-tick log, streamed (fields.json + one raw float64 file per field)
      events.jsonl    safety and loop events as they happen
      log.npz         the same log, assembled at close (see loop.control_loop.RunLog)
      summary.json    status and end reason; fell or not, commanded vs achieved velocity per segment,
                      stage timings, RTF
      velocity.png    commanded vs achieved velocity and pelvis height
      video.mp4       when headless rendering is available (EGL or OSMesa)
"""

from __future__ import annotations

import dataclasses
import itertools
import json
import signal
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from g1_control.errors import Interrupted
from g1_control.interfaces import InputDevice
from g1_control.launch.builder import build_loop, make_sim_backend, timeline_of
from g1_control.launch.overlay import overlay_lines
from g1_control.launch.run_folder import RunFolder, interrupt_on_signals
from g1_control.launch.schema import LaunchFile
from g1_control.loop.control_loop import ControlLoop, first_fault
from g1_control.robot import g1
from g1_control.teleop.scripted import Segment

if TYPE_CHECKING:
    from g1_control.sim.mujoco_backend import MujocoBackend

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


def run(launch: LaunchFile, *, out_root: Path | None = None, video: bool | None = None,
        progress: bool = True, viewer: bool = False, web_port: int | None = None,
        input_device: InputDevice | None = None, end_with_program: bool = True) -> RunResult:
    """Run `launch` to the end (or a fall); write the run folder when `out_root` is given, as the run
    goes (g1_control/launch/run_folder.py), closed on the end, a fall, SIGINT or SIGTERM.

    viewer: the MuJoCo viewer; web_port: the browser view (g1_control/sim/web.py) on that port;
    input_device: instead of the launch file's input (g1 say hands in its program input).
    end_with_program: a program run ends PROGRAM_END_HOLD_S after its last step (False: it runs
    the launch file's whole duration, as the deploy's dry run does).
    """
    segments = timeline_of(launch)
    sim = make_sim_backend(launch)
    loop = build_loop(launch, backend=sim, input_device=input_device)
    folder = RunFolder.create(Path(out_root), launch) if out_root is not None else None
    if folder is None:
        return _run_loop(launch, sim, loop, segments, None, progress, viewer, web_port,
                         end_with_program=end_with_program)
    try:
        with interrupt_on_signals():
            return _run_loop(launch, sim, loop, segments, folder, progress, viewer, web_port, video,
                             end_with_program=end_with_program)
    except BaseException as exc:
        if not folder.closed:  # an error before the loop ran, or while closing: say so
            folder.finish("error" if not isinstance(exc, KeyboardInterrupt) else "interrupted",
                          f"{type(exc).__name__}: {exc}", {})
        raise


def _run_loop(launch: LaunchFile, sim: MujocoBackend, loop: ControlLoop, segments: list[Segment],
              folder: RunFolder | None, progress: bool, viewer: bool, web_port: int | None,
              video: bool | None = None, end_with_program: bool = True) -> RunResult:
    if folder is not None:
        folder.attach(loop)
    loop.reset()
    duration = launch.total_duration_s
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=round(duration, 1), unit="sim s", desc=launch.name, bar_format="{l_bar}{bar}| {n:.1f}/{total} sim s [{elapsed}<{remaining}]")
    ticks_per_update = int(loop.rates.lowlevel_hz)
    watcher = None
    if launch.tracker.type == "layer":  # goals: judged from ground truth (g1_control/launch/outcomes.py)
        from g1_control.launch.outcomes import GoalWatcher

        watcher = GoalWatcher(loop)
        loop.goal_watcher = watcher  # type: ignore[attr-defined]  # the run folder saves what it saw
    view = _open_viewer(sim) if viewer else None
    web = _open_web(sim, web_port, launch.name) if web_port is not None else None

    def on_tick(i: int) -> None:
        if watcher is not None:
            watcher.tick(i)
        if bar is not None and (i + 1) % ticks_per_update == 0:
            bar.update(1.0)
            if loop.faulted:
                bar.set_postfix_str("FELL" if loop.fell else "DAMPING")
        if view is not None and (i + 1) % 10 == 0 and time.perf_counter() - last_sync[0] > 1 / 30:
            _update_viewer(view, loop)  # at most 30 Hz: sync() waits for the viewer's render
            last_sync[0] = time.perf_counter()
        if web is not None and (i + 1) % 10 == 0 and time.perf_counter() - last_web[0] > 1 / 25:
            web.show(sim.data.qpos, "\n".join(": ".join(kv) for kv in zip(*map(str.splitlines,
                                                                                    overlay_lines(loop)))))
            last_web[0] = time.perf_counter()

    last_sync = [0.0]
    last_web = [0.0]
    t0 = time.perf_counter()
    stop = (lambda: not view.is_running()) if view is not None else None
    program = program_input(loop)
    if program is not None and end_with_program:  # ends PROGRAM_END_HOLD_S after its last step
        from g1_control.launch.schema import PROGRAM_END_HOLD_S

        viewer_closed = stop

        def stop() -> bool:
            over = program.ended_s is not None and loop.now_s() - program.ended_s >= PROGRAM_END_HOLD_S
            return over or (viewer_closed is not None and viewer_closed())
    interrupted: KeyboardInterrupt | None = None
    try:
        loop.scheduler.run(round(duration * loop.rates.lowlevel_hz), stop=stop, progress=on_tick)
    except KeyboardInterrupt as exc:
        if folder is None:
            raise
        interrupted = exc if isinstance(exc, Interrupted) else Interrupted(signal.SIGINT)
    finally:
        wall = time.perf_counter() - t0
        if bar is not None:
            bar.close()
        if view is not None:
            view.close()
        if web is not None:
            web.close()
        loop.input.close()
        loop.backend.close()
    log = folder.close_log(loop) if folder is not None else loop.log.arrays()
    result = _result(launch, loop, segments, wall, log)
    if watcher is not None:
        result.extra["goals"] = watcher.outcomes()
    if program is not None:
        from g1_control.program.device import record_dict

        finish_program_verdicts(program.records, result.extra.get("goals", []), result.fall)

        result.extra["program"] = {"steps": [record_dict(r) for r in program.records],
                                   "finished": program.done and not program.runner.stopped,
                                   "pose": program.pose_source}
    if folder is not None:
        write_run_folder(result, launch, loop, folder, log, video, interrupted)
    if interrupted is not None:
        raise interrupted
    return result


def finish_program_verdicts(records: list, goals: list[dict], fall: dict | None) -> None:
    """After a run: goal steps take the execution layer's ground-truth verdict (program.judge.goal_verdict
    on launch/outcomes.py's figures); a step the robot fell in, or after, is missed whatever it measured."""
    from g1_control.program.judge import goal_verdict

    by_goal = {o["goal_id"]: o for o in goals}
    for r in records:
        if r.goal_id in by_goal:
            r.verdict = goal_verdict(by_goal[r.goal_id])
        if fall is not None and r.verdict is not None and r.outcome.ended_s >= fall["t_s"]:
            r.verdict.ok = False
            r.verdict.text += f"; FELL at {fall['t_s']:.2f} s"


def program_input(loop: ControlLoop):
    """The loop's ProgramInput (g1_control/program/device.py), or None."""
    from g1_control.program.device import ProgramInput

    return loop.input if isinstance(loop.input, ProgramInput) else None


def _open_viewer(sim: MujocoBackend):
    from g1_control.sim.viewer import open_viewer

    return open_viewer(sim.model, sim.data)


def _open_web(sim: MujocoBackend, port: int, title: str):
    from g1_control.sim.web import WebView

    web = WebView(sim.model, port=port, title=title)
    print(f"browser view: {web.url}", flush=True)
    return web


def _update_viewer(view, loop: ControlLoop) -> None:
    from g1_control.sim.viewer import update_viewer

    update_viewer(view, *overlay_lines(loop))


def _result(launch: LaunchFile, loop: ControlLoop, segments: list[Segment], wall: float,
            log: dict[str, np.ndarray]) -> RunResult:
    est_rms = None
    valid = ~np.isnan(log["velocity_true"][:, 0])
    if valid.sum() > 10:
        err = log["velocity_est"][valid, :2] - log["velocity_true"][valid, :2]
        est_rms = float(np.sqrt((err**2).sum(axis=1).mean()))
    fall = loop.fall
    return RunResult(
        name=launch.name, fell=fall is not None, fall=dataclasses.asdict(fall) if fall else None,
        duration_s=loop.time_s, wall_s=wall,
        segments=segment_results(log, segments), timings=loop.scheduler.report(),
        deadline_misses=loop.scheduler.deadline_misses, overruns=loop.scheduler.overruns,
        events=[dataclasses.asdict(e) for e in loop.events], estimator_rms_mps=est_rms, chain=dict(loop.chain),
    )


def write_run_folder(result: RunResult, launch: LaunchFile, loop: ControlLoop, folder: RunFolder,
                     log: dict[str, np.ndarray], video: bool | None,
                     interrupted: KeyboardInterrupt | None = None) -> Path:
    """Close `folder`: log.npz, the plot, the video (not after a signal), summary.json with the end reason."""
    run_dir = folder.run_dir
    result.run_dir = run_dir
    folder.write_npz(log)
    watcher = getattr(loop, "goal_watcher", None)
    if watcher is not None:  # ground truth of the goals: hand points, soles, boxes (launch/outcomes.py)
        np.savez_compressed(run_dir / "truth.npz", **watcher.arrays())
    if launch.output.plot:
        from g1_control.launch.plots import plot_run

        plot_run(log, result, run_dir / "velocity.png")
    want_video = interrupted is None and (video if video is not None else launch.output.video in (True, "auto"))
    if want_video:
        from g1_control.launch.overlay import run_overlay_rows
        from g1_control.sim.render import render_video

        overlay = run_overlay_rows(log, result.events, [dataclasses.asdict(s) for s in result.segments])
        backend = render_video(run_dir / "log.npz", run_dir / "video.mp4", launch.output.video_fps,
                               launch.output.video_size, overlay=overlay, extra=_scene_arrays(launch, loop))
        result.video = str(run_dir / "video.mp4") if backend else None
        result.extra["render_backend"] = backend
    trip = first_fault(result.events)
    if interrupted is not None:
        status, reason = "interrupted", str(interrupted)
    elif trip is not None:
        status, reason = "fault", f"{trip['kind']}: {trip['detail']}"
    else:
        status, reason = "completed", f"duration reached ({result.duration_s:.1f} s)"
    folder.finish(status, reason, summary_dict(result))
    return run_dir


def _scene_arrays(launch: LaunchFile, loop: ControlLoop) -> dict | None:
    """The scene and where its boxes were (ground truth), for the video; None without a scene."""
    watcher = getattr(loop, "goal_watcher", None)
    if launch.scene.empty or watcher is None:
        return None
    truth = watcher.arrays()
    out = {"scene_json": np.asarray(json.dumps(dataclasses.asdict(launch.scene))), "object_t_s": truth["t_s"]}
    for key, rows in truth.items():
        if key.startswith("box_") and len(rows):
            out["object_" + key.removeprefix("box_")] = rows
    return out


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
        from g1_control.launch.outcomes import outcome_line

        lines += ["", "goals (ground truth):"] + ["  " + outcome_line(o) for o in result.extra["goals"]]
    if result.extra.get("program"):
        lines += ["", program_summary(result.extra["program"])]
    if result.run_dir:
        lines.append(f"run folder: {result.run_dir}" + (f" (video: {Path(result.video).name})" if result.video else ""))
    return "\n".join(lines)
