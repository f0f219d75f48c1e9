"""Look at a recorded run or a motion clip again: `g1 replay RUN`, `g1 view CLIP`.

Both become a Playback (times, base pose, joints, one overlay text per frame and what else to
draw: a ReplayScene, g1_control/sim/replay_scene.py), which goes to the MuJoCo viewer (with a
display), a headless MP4 or one PNG frame (g1_control/sim/render.py), or the browser
(g1_control/sim/web.py). A run's scene comes from the launch.yaml in its folder, its boxes move
as truth.npz recorded them (ground truth, every tick); a clip's scene shapes and handled object
come from the clip. A run's overlay shows the command, the achieved velocity
(ground truth, averaged over one gait cycle) and the safety state, rebuilt from log.npz and the
events in summary.json; a clip's overlay shows its name, frame, style and foot contacts.
"""

from __future__ import annotations

import json
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from g1_control.errors import G1ControlError
from g1_control.sim.replay_scene import ReplayScene, replay_model


@dataclass
class Playback:
    title: str
    t_s: np.ndarray
    base_pos_m: np.ndarray
    base_quat_wxyz: np.ndarray
    q_rad: np.ndarray
    overlay: list[str]
    scene: ReplayScene | None = None
    """What is drawn besides the robot (None: the robot alone)."""

    @property
    def duration_s(self) -> float:
        return float(self.t_s[-1] - self.t_s[0]) if len(self.t_s) else 0.0

    def qpos(self, i: int) -> np.ndarray:
        return np.concatenate([self.base_pos_m[i], self.base_quat_wxyz[i], self.q_rad[i]])

    def index_at(self, t_s: float) -> int:
        return int(np.searchsorted(self.t_s, t_s).clip(0, len(self.t_s) - 1))


def is_run_log(path: Path) -> bool:
    if path.is_dir():
        return (path / "log.npz").is_file()
    if path.suffix != ".npz" or not path.is_file():
        return False
    with np.load(path) as data:
        return {"t_s", "base_pos_m", "command"} <= set(data.files)


def from_run(path: str | Path) -> Playback:
    """A run folder written by `g1 launch` (or its log.npz)."""
    path = Path(path)
    folder = path if path.is_dir() else path.parent
    log_path = path / "log.npz" if path.is_dir() else path
    if not log_path.is_file():
        raise G1ControlError(f"{path}: no log.npz here; give a run folder written by g1 launch (runs/NAME-TIME)")
    with np.load(log_path) as data:
        log = {k: data[k] for k in data.files}
    if len(log["t_s"]) == 0 or np.isnan(log["base_pos_m"]).all():
        raise G1ControlError(f"{log_path}: the log has no base pose to replay (a robot run logs no ground truth)")
    summary = {}
    if (folder / "summary.json").is_file():
        summary = json.loads((folder / "summary.json").read_text())
    from g1_control.report.overlay import run_overlay_rows

    rows = run_overlay_rows(log, summary.get("events", []), summary.get("segments", []))
    title = f"run {summary.get('name', folder.name)}"
    return Playback(title, log["t_s"], log["base_pos_m"], log["base_quat_wxyz"], log["q_rad"], rows,
                    run_scene(folder))


def run_scene(folder: Path) -> ReplayScene | None:
    """The scene of the launch.yaml a run folder holds, its boxes and bottles where truth.npz recorded
    them (None: the run had no scene; one without recorded poses stays where the scene put it)."""
    import yaml

    launch_path = folder / "launch.yaml"
    if not launch_path.is_file():
        return None
    try:
        scene = (yaml.safe_load(launch_path.read_text()) or {}).get("scene") or {}
    except yaml.YAMLError as exc:
        raise G1ControlError(f"{launch_path}: not readable as YAML ({exc})") from None
    truth: dict[str, np.ndarray] = {}
    if (folder / "truth.npz").is_file():
        with np.load(folder / "truth.npz") as data:
            truth = {k: data[k] for k in data.files}
    return scene_with_truth(scene, truth)


def scene_with_truth(scene, truth: dict[str, np.ndarray]) -> ReplayScene | None:
    """A ReplayScene of `scene` (a SceneConfig or its dict) with the boxes' and bottles' recorded poses
    from `truth` (report/outcomes.py GoalWatcher.arrays: t_s, box_<name>, bottle_<name>); None for an
    empty scene."""
    import dataclasses

    as_dict = dataclasses.asdict(scene) if dataclasses.is_dataclass(scene) and not isinstance(scene, type) \
        else dict(scene)
    if not any(as_dict.get(k) for k in ("tables", "platforms", "boxes", "bottles")):
        return None
    poses = {k.split("_", 1)[1]: v for k, v in truth.items() if k.startswith(("box_", "bottle_")) and len(v)}
    return ReplayScene(scene_json=json.dumps(as_dict), object_t_s=truth.get("t_s", np.zeros(0)),
                       object_poses=poses)


def from_clip(path: str | Path) -> Playback:
    """Any G1 motion clip the project reads or writes: motion-library npz, BeyondMimic npz, Unitree
    CSV; a run's log.npz is replayed as a run."""
    path = Path(path)
    if is_run_log(path):
        return from_run(path)
    from g1_control.motion.clip import MotionClip
    from g1_control.motion.formats.dispatch import load_motion

    clip = load_motion(path)
    if not isinstance(clip, MotionClip):
        raise G1ControlError(f"{path}: human motion capture, not a G1 clip; retarget it first "
                             f"(g1 retarget {path} -o clip.npz), then g1 view clip.npz")
    n = clip.root_pos_w_m.shape[0]
    t = np.arange(n) / clip.fps
    name = clip.source or path.name
    rows = []
    for i in range(n):
        left, right = (bool(c) for c in clip.contacts[i][:2]) if clip.contacts.size else (False, False)
        feet = " ".join(s for s, on in (("L", left), ("R", right)) if on) or "-"
        rows.append(f"{name}\nframe {i + 1}/{n}   t {t[i]:5.2f} s   {clip.fps:g} fps\n"
                    f"style {clip.style}   feet in contact {feet}")
    return Playback(f"clip {name}", t, clip.root_pos_w_m, clip.root_quat_wxyz, clip.joint_pos_rad, rows,
                    clip_scene(clip, t))


def clip_scene(clip, t_s: np.ndarray) -> ReplayScene | None:
    """A clip's static scene shapes (world coordinates) and the object it handles, moving as the
    clip's object track says; None when it has neither."""
    shapes = {f"{i}_{s.name or 'shape'}": s.vertices() for i, s in enumerate(clip.scene)}
    movers, poses = {}, {}
    if clip.object is not None:
        name = f"object_{clip.object.shape.name or 'object'}"
        movers[name] = clip.object.shape.vertices()
        poses[name] = np.c_[clip.object.pos_w_m, clip.object.quat_wxyz]
    if not shapes and not movers:
        return None
    return ReplayScene(shapes_w_m=shapes, movers_m=movers, object_t_s=t_s, object_poses=poses)


def _trajectory_file(pb: Playback, folder: Path) -> Path:
    path = folder / "trajectory.npz"
    scene = pb.scene.arrays() if pb.scene is not None else {}
    np.savez(path, t_s=pb.t_s, base_pos_m=pb.base_pos_m, base_quat_wxyz=pb.base_quat_wxyz, q_rad=pb.q_rad,
             overlay=np.asarray(pb.overlay, dtype=str), **scene)  # type: ignore[arg-type]  # numpy's stub: see run_folder
    return path


def write_video(pb: Playback, out: Path, *, fps: float = 25.0, size=(640, 480), quiet: bool = False) -> str:
    """Headless MP4 with the overlay; returns the GL backend used."""
    from g1_control.sim.render import render_video

    with tempfile.TemporaryDirectory(prefix="g1-replay-") as tmp:
        backend = render_video(_trajectory_file(pb, Path(tmp)), out, fps, size, quiet)
    if backend is None:
        raise G1ControlError("no headless rendering here (needs EGL or OSMesa: apt install libegl1 libosmesa6)")
    return backend


def write_frame(pb: Playback, at_s: float, out: Path, *, size=(640, 480)) -> str:
    """One PNG frame at `at_s` seconds, with the overlay; returns the GL backend used."""
    from g1_control.sim.render import render_video

    with tempfile.TemporaryDirectory(prefix="g1-replay-") as tmp:
        backend = render_video(_trajectory_file(pb, Path(tmp)), out, 1.0, size, True, frame_at_s=at_s)
    if backend is None:
        raise G1ControlError("no headless rendering here (needs EGL or OSMesa: apt install libegl1 libosmesa6)")
    return backend


def pose(pb: Playback, model, data, i: int) -> None:
    """Frame `i` of `pb` into `data` of replay_model(pb.scene): the robot's base and joints, and
    each moving box or object where it was then."""
    data.qpos[:7 + pb.q_rad.shape[1]] = pb.qpos(i)
    if pb.scene is not None:
        pb.scene.pose(model, data, float(pb.t_s[i]))


def _play(pb: Playback, show, running, speed: float, repeat: bool) -> None:
    """Call show(i) at the frames' own pace (times `speed`) until the end, or forever with `repeat`."""
    while True:
        start = time.perf_counter()
        for i in range(len(pb.t_s)):
            if not running():
                return
            wait = (pb.t_s[i] - pb.t_s[0]) / speed - (time.perf_counter() - start)
            if wait > 0:
                time.sleep(wait)
            elif i % 4:  # behind: skip drawing some frames, keep the clock
                continue
            show(i)
        if not repeat:
            return


def play_viewer(pb: Playback, *, speed: float = 1.0, repeat: bool = False) -> None:
    """The MuJoCo viewer (needs a display), the overlay in its top-left corner."""
    import mujoco

    from g1_control.sim.viewer import open_viewer, update_viewer

    model = replay_model(pb.scene)
    data = mujoco.MjData(model)
    view = open_viewer(model, data)

    def show(i: int) -> None:
        pose(pb, model, data, i)
        mujoco.mj_forward(model, data)
        update_viewer(view, pb.overlay[i], "")

    try:
        _play(pb, show, view.is_running, speed, repeat)
    finally:
        view.close()


def serve_web(pb: Playback, *, port: int = 8080, host: str = "127.0.0.1", speed: float = 1.0,
              repeat: bool = True, on_ready=None) -> None:
    """Play in the browser (viser) until interrupted (or once through without `repeat`)."""
    from g1_control.sim.web import WebView

    view = WebView(replay_model(pb.scene), port=port, host=host, title=pb.title)
    if on_ready is not None:
        on_ready(view)

    def show(i: int) -> None:
        pose(pb, view.model, view.data, i)
        view.show(view.data.qpos.copy(), pb.overlay[i])

    try:
        _play(pb, show, lambda: True, speed, repeat)
    finally:
        view.close()
