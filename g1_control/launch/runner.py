"""Build the loop a launch file describes, run it, and write the run folder as it goes
(g1_control/report/run_folder.py; closed on the end, a fall, SIGINT or SIGTERM; the run's figures
and printed report: g1_control/report/results.py):

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

import contextlib
import dataclasses
import signal
import time
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from g1_control.errors import Interrupted
from g1_control.interfaces import InputDevice
from g1_control.launch.builder import build_loop, make_sim_backend, timeline_of
from g1_control.launch.schema import LaunchFile
from g1_control.loop.control_loop import ControlLoop, first_fault
from g1_control.loop.priority import frozen_heap
from g1_control.report.overlay import overlay_lines
from g1_control.report.results import RunResult, run_result, summary_dict
from g1_control.report.run_folder import RunFolder, interrupt_on_signals
from g1_control.teleop.scripted import Segment

if TYPE_CHECKING:
    from g1_control.report.outcomes import GoalWatcher
    from g1_control.sim.mujoco_backend import MujocoBackend



def run(launch: LaunchFile, *, out_root: Path | None = None, video: bool | None = None,
        progress: bool = True, viewer: bool = False, web_port: int | None = None,
        input_device: InputDevice | None = None, end_with_program: bool = True) -> RunResult:
    """Run `launch` to the end (or a fall); write the run folder when `out_root` is given, as the run
    goes (g1_control/report/run_folder.py), closed on the end, a fall, SIGINT or SIGTERM.

    viewer: the MuJoCo viewer; web_port: the browser view (g1_control/sim/web.py) on that port;
    input_device: instead of the launch file's input (g1 say hands in its program input).
    end_with_program: a program run ends PROGRAM_END_HOLD_S after its last step (False: it runs
    the launch file's whole duration, as the deploy's dry run does).
    """
    segments = timeline_of(launch)
    sim = make_sim_backend(launch)
    if sim.draw is not None and progress:  # recorded too: the run summary's chain.backend
        print(f"randomised robot (backend.randomize): {sim.draw.summary()}", flush=True)
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
    if launch.executes_goals:  # goals: judged from ground truth (g1_control/report/outcomes.py)
        from g1_control.report.outcomes import GoalWatcher

        watcher = GoalWatcher(loop)  # the run folder saves what it saw
    view = _open_viewer(sim) if viewer else None
    web = _open_web(sim, web_port, launch.name) if web_port is not None else None

    pushes = sorted(launch.pushes, key=lambda p: p.at_s)

    def on_tick(i: int) -> None:
        if watcher is not None:
            watcher.tick(i)
        if pushes and sim.data.time >= pushes[0].at_s:
            _push(sim, pushes.pop(0))
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
    # On the wall clock, no full collection of the caller's heap inside the loop (loop/priority.py): in a
    # long-lived process (a test session's, a notebook's) one takes 50 ms or more, and the state goes stale.
    heap = frozen_heap() if loop.scheduler.wallclock else contextlib.nullcontext()
    try:
        with heap:
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
        loop.generator.close()
        loop.backend.close()
    log = folder.close_log(loop) if folder is not None else loop.log.arrays()
    result = run_result(launch.name, loop, segments, wall, log)
    if watcher is not None:
        result.extra["goals"] = watcher.outcomes()
    if launch.pushes:
        result.extra["pushes"] = push_outcomes(launch.pushes, log, result.fall)
    by_style = style_figures(log, result.fall)
    if by_style:
        result.extra["by_style"] = by_style
    if program is not None:
        from g1_control.program.device import record_dict

        finish_program_verdicts(program.records, result.extra.get("goals", []), result.fall)

        result.extra["program"] = {"steps": [record_dict(r) for r in program.records],
                                   "finished": program.done and not program.runner.stopped,
                                   "pose": program.pose_source}
    if folder is not None:
        write_run_folder(result, launch, loop, folder, log, video, interrupted, watcher)
    if interrupted is not None:
        raise interrupted
    return result


def style_figures(log: dict[str, np.ndarray], fall: dict | None) -> dict[str, dict]:
    """Per operator style, up to a fall: the upper body vs the plan (RMS) and the footsteps vs the plan's
    (report/footsteps.py), for runs with a reference and ground truth."""
    from g1_control.report.footsteps import footsteps_by_style
    from g1_control.report.results import upper_body_rms_by_style

    if not len(log["t_s"]):
        return {}
    window = np.ones(len(log["t_s"]), dtype=bool) if fall is None else log["t_s"] < fall["t_s"]
    cut = {k: (v[window] if k != "style_names" else v) for k, v in log.items()}
    out: dict[str, dict] = {}
    for name, ub in upper_body_rms_by_style(cut).items():
        out.setdefault(name, {})["upper_body_rms_rad"] = ub["rms_rad"]
    for name, steps in footsteps_by_style(cut).items():
        out.setdefault(name, {})["footsteps"] = steps
    return out


def _push(sim: MujocoBackend, push) -> None:
    from g1_control.rotations import heading_to_world, yaw_of

    force_w = heading_to_world(np.asarray(push.force_h_n, dtype=float), yaw_of(sim.data.qpos[3:7]))
    sim.push(force_w, push.duration_s)


PUSH_WINDOW_S = 3.0
"""A push is judged over this long after it starts."""
UPRIGHT_TILT_RAD = 0.1
"""Upright again: the pelvis within this of vertical (standing and walking stay within ~0.05)."""


def push_outcomes(pushes: list, log: dict[str, np.ndarray], fall: dict | None) -> list[dict]:
    """Per push, from the simulator's ground truth in the log: recovered (no fall from the push to the
    end of its window, upright again), the peak tilt, how far the pelvis went in the window and
    when it was upright again."""
    t, tilt, pos = log["t_s"], log["tilt_rad"], log["base_pos_m"]
    out = []
    for p in pushes:
        window = (t >= p.at_s) & (t <= p.at_s + PUSH_WINDOW_S)
        fell = fall is not None and fall["t_s"] >= p.at_s and (fall["t_s"] <= p.at_s + PUSH_WINDOW_S)
        entry = {"label": p.label, "at_s": p.at_s, "force_h_n": list(p.force_h_n), "duration_s": p.duration_s,
                 "fell": bool(fell or (fall is not None and fall["t_s"] < p.at_s))}
        if window.any() and not entry["fell"]:
            tw, tilt_w = t[window], tilt[window]
            peak = int(np.argmax(tilt_w))
            after = np.flatnonzero(tilt_w[peak:] <= UPRIGHT_TILT_RAD)
            entry.update(peak_tilt_rad=float(tilt_w[peak]), moved_m=float(np.linalg.norm(pos[window][-1, :2]
                                                                                          - pos[window][0, :2])),
                         upright_after_s=float(tw[peak + after[0]] - p.at_s) if after.size else None)
        entry["recovered"] = not entry["fell"] and entry.get("upright_after_s") is not None
        out.append(entry)
    return out


def finish_program_verdicts(records: list, goals: list[dict], fall: dict | None) -> None:
    """After a run: goal steps take the execution layer's ground-truth verdict (program.judge.goal_verdict
    on report/outcomes.py's figures); a step the robot fell in, or after, is missed whatever it measured."""
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


def write_run_folder(result: RunResult, launch: LaunchFile, loop: ControlLoop, folder: RunFolder,
                     log: dict[str, np.ndarray], video: bool | None,
                     interrupted: KeyboardInterrupt | None = None, watcher: GoalWatcher | None = None) -> Path:
    """Close `folder`: log.npz, the plot, the video (not after a signal), summary.json with the end reason;
    with a goal watcher (report/outcomes.py), truth.npz and the scene's boxes in the video."""
    run_dir = folder.run_dir
    result.run_dir = run_dir
    folder.write_npz(log)
    if watcher is not None:  # ground truth of the goals: hand points, soles, boxes (report/outcomes.py)
        np.savez_compressed(run_dir / "truth.npz", **watcher.arrays())  # type: ignore[arg-type]
    if launch.output.plot:
        from g1_control.report.plots import plot_run

        plot_run(log, result, run_dir / "velocity.png")
    want_video = interrupted is None and (video if video is not None else launch.output.video in (True, "auto"))
    if want_video:
        from g1_control.report.overlay import run_overlay_rows
        from g1_control.sim.render import render_video

        overlay = run_overlay_rows(log, result.events, [dataclasses.asdict(s) for s in result.segments])
        backend = render_video(run_dir / "log.npz", run_dir / "video.mp4", launch.output.video_fps,
                               launch.output.video_size, overlay=overlay, extra=_scene_arrays(launch, watcher))
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


def _scene_arrays(launch: LaunchFile, watcher: GoalWatcher | None) -> dict | None:
    """The scene and where its boxes were (ground truth), for the video; None without a scene."""
    from g1_control.report.replay import scene_with_truth

    scene = scene_with_truth(launch.scene, watcher.arrays() if watcher is not None else {})
    return scene.arrays() if scene is not None else None
