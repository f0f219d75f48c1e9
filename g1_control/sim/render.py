"""Headless video of a run or a clip: replays base pose and joints through MuJoCo's renderer.

Runs in its own process (`python -m g1_control.sim.render TRAJ.npz OUT.mp4`; users call it through
`g1 launch`, `g1 replay` and `g1 view`) because MuJoCo picks its OpenGL backend once per process:
`render_video` tries EGL, then OSMesa (Debian's libosmesa6), and reports which one worked.
Without a GPU both render in software; without multisampling, shadows and reflections that costs
~0.04 s per 480x360 frame instead of ~1 s.

The trajectory file holds t_s, base_pos_m, base_quat_wxyz and q_rad per row (a run's log.npz is
one) and optionally `overlay`: one text per row, drawn in the frame's top-left corner, and what
else to draw (a ReplayScene's arrays, g1_control/sim/replay_scene.py): `scene_json` (a SceneConfig,
g1_control/scene.py: its tables, platforms and boxes), clip shapes, and `object_t_s` with
`object_<box>` (position + quaternion per sample: where each box was).
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
from collections.abc import Sequence
from pathlib import Path

GL_BACKENDS = ("egl", "osmesa")
TRAJECTORY_KEYS = ("t_s", "base_pos_m", "base_quat_wxyz", "q_rad")


def render_video(log_path: Path, out_path: Path, fps: float = 10.0, size=(480, 360), quiet: bool = False,
                 overlay: Sequence[str] | None = None, frame_at_s: float | None = None,
                 extra: dict | None = None) -> str | None:
    """Render the trajectory in `log_path` to `out_path` (MP4); returns the GL backend used, or None
    if none works. `overlay`: one text per row of the log, drawn on each frame. `frame_at_s`: write
    only the frame at that time, as a PNG. `extra`: more arrays for the trajectory file (the scene
    and its boxes, module docstring)."""
    if overlay is not None or extra:
        import numpy as np

        with np.load(log_path) as log, tempfile.TemporaryDirectory(prefix="g1-render-") as tmp:
            traj = Path(tmp) / "trajectory.npz"
            more = dict(extra or {})
            if overlay is not None:
                more["overlay"] = np.asarray(list(overlay), dtype=str)
            np.savez(traj, **more, **{k: log[k] for k in TRAJECTORY_KEYS})
            return render_video(traj, out_path, fps, size, quiet, None, frame_at_s)
    cmd = [sys.executable, "-m", "g1_control.sim.render", str(log_path), str(out_path),
           "--fps", str(fps), "--size", str(size[0]), str(size[1])]
    if frame_at_s is not None:
        cmd += ["--frame-at", str(frame_at_s)]
    for backend in GL_BACKENDS:
        env = dict(os.environ, MUJOCO_GL=backend, PYOPENGL_PLATFORM=backend)
        # Probe quietly (a missing GL stack fails with a long traceback), then render with progress.
        probe = subprocess.run(cmd + ["--probe"], env=env, stderr=subprocess.PIPE, text=True, check=False)
        if probe.returncode != 0:
            if not quiet:
                last = (probe.stderr or "").strip().splitlines()[-1:] or ["no output"]
                print(f"render: {backend} unavailable ({last[0]})", file=sys.stderr)
            continue
        proc = subprocess.run(cmd + (["--quiet"] if quiet else []), env=env, check=False)
        if proc.returncode == 0 and out_path.is_file():
            return backend
    return None


def _video_model(scene=None):
    from g1_control.sim.replay_scene import replay_model

    return replay_model(scene, video=True)


def tracking_camera(model):
    """The video's camera: 3 m from the pelvis, from the front left, slightly above."""
    import mujoco

    camera = mujoco.MjvCamera()
    camera.type = mujoco.mjtCamera.mjCAMERA_TRACKING
    camera.trackbodyid = model.body("pelvis").id
    camera.distance, camera.elevation, camera.azimuth = 3.0, -15.0, 135.0
    return camera


def _cheap_scene(renderer) -> None:
    import mujoco

    renderer.scene.flags[mujoco.mjtRndFlag.mjRND_SHADOW] = False
    renderer.scene.flags[mujoco.mjtRndFlag.mjRND_REFLECTION] = False


def _probe(size: tuple[int, int]) -> None:
    """Create a renderer and draw one frame: fails fast where this GL backend does not work."""
    import mujoco

    model = _video_model()
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    renderer = mujoco.Renderer(model, height=size[1], width=size[0])
    try:
        renderer.update_scene(data)
        _cheap_scene(renderer)
        renderer.render()
    finally:
        renderer.close()


def draw_overlay(frame, text: str):
    """`frame` (H, W, 3 uint8) with `text` in a dark box in its top-left corner."""
    import numpy as np
    from PIL import Image, ImageDraw, ImageFont

    if not text:
        return frame
    image = Image.fromarray(frame)
    draw = ImageDraw.Draw(image, "RGBA")
    try:
        font = ImageFont.load_default(size=max(10, frame.shape[0] // 30))
    except TypeError:  # Pillow < 10.1: one fixed bitmap font
        font = ImageFont.load_default()
    _, _, right, bottom = draw.multiline_textbbox((8, 6), text, font=font, spacing=3)
    draw.rectangle((2, 2, right + 6, bottom + 6), fill=(0, 0, 0, 150))
    draw.multiline_text((8, 6), text, font=font, fill=(255, 255, 255, 255), spacing=3)
    return np.asarray(image)


def _render(log_path: Path, out_path: Path, fps: float, size: tuple[int, int], quiet: bool,
            frame_at_s: float | None = None) -> None:
    import imageio.v2 as imageio
    import mujoco
    import numpy as np
    from tqdm import tqdm

    from g1_control.sim.replay_scene import ReplayScene

    log = np.load(log_path)
    t, pos, quat, q = log["t_s"], log["base_pos_m"], log["base_quat_wxyz"], log["q_rad"]
    overlay = log["overlay"] if "overlay" in log.files else None
    if len(t) == 0 or np.isnan(pos).all():
        raise SystemExit("log has no ground-truth base pose to replay")
    scene = ReplayScene.from_arrays({k: log[k] for k in log.files if k not in TRAJECTORY_KEYS})
    model = _video_model(scene)
    data = mujoco.MjData(model)
    renderer = mujoco.Renderer(model, height=size[1], width=size[0])
    camera = tracking_camera(model)

    def frame(i: int):
        data.qpos[:3], data.qpos[3:7], data.qpos[7:7 + q.shape[1]] = pos[i], quat[i], q[i]
        scene.pose(model, data, float(t[i]))
        mujoco.mj_forward(model, data)  # also the subtree CoM the tracking camera follows
        renderer.update_scene(data, camera)
        _cheap_scene(renderer)
        image = renderer.render()
        return draw_overlay(image, str(overlay[i])) if overlay is not None else image

    try:
        if frame_at_s is not None:
            i = int(np.searchsorted(t, frame_at_s).clip(0, len(t) - 1))
            imageio.imwrite(out_path, frame(i))
            return
        frame_times = np.arange(t[0], t[-1], 1.0 / fps) if len(t) > 1 else t[:1]
        idx = np.searchsorted(t, frame_times).clip(0, len(t) - 1)
        # Not `with ... as writer`: imageio's stub types __enter__ as its base class, which has no append_data.
        writer = imageio.get_writer(out_path, fps=fps, codec="libx264", quality=7, macro_block_size=8)
        with writer:
            for i in tqdm(idx, desc="render", unit="frame", disable=quiet):
                writer.append_data(frame(int(i)))
    finally:
        renderer.close()  # before interpreter exit, or its destructor complains noisily


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description="Render a trajectory (a run's log.npz) to MP4, headless "
                                     "(users: g1 replay RUN, g1 view CLIP).")
    parser.add_argument("log", type=Path)
    parser.add_argument("out", type=Path)
    parser.add_argument("--fps", type=float, default=10.0)
    parser.add_argument("--size", type=int, nargs=2, default=(480, 360), metavar=("W", "H"))
    parser.add_argument("--quiet", action="store_true")
    parser.add_argument("--probe", action="store_true", help="only check that rendering works here")
    parser.add_argument("--frame-at", type=float, help="write only the frame at this time (s) as an image")
    args = parser.parse_args(argv)
    if args.probe:
        _probe(tuple(args.size))
        return 0
    _render(args.log, args.out, args.fps, tuple(args.size), args.quiet, args.frame_at)
    return 0


if __name__ == "__main__":
    sys.exit(main())
