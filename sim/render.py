"""Headless video of a run: replays logged base pose and joints through MuJoCo's renderer.

Runs in its own process (`python -m g1_control.sim.render LOG.npz OUT.mp4`) because MuJoCo picks
its OpenGL backend once per process: `render_video` tries EGL, then OSMesa (Debian's
libosmesa6, software rendering, ~0.3 s per frame), and reports which one worked.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
from pathlib import Path

GL_BACKENDS = ("egl", "osmesa")


def render_video(log_path: Path, out_path: Path, fps: float = 10.0, size=(480, 360), quiet: bool = False) -> str | None:
    """Render `log_path` to `out_path`; returns the GL backend used, or None if none works."""
    for backend in GL_BACKENDS:
        env = dict(os.environ, MUJOCO_GL=backend, PYOPENGL_PLATFORM=backend)
        cmd = [sys.executable, "-m", "g1_control.sim.render", str(log_path), str(out_path),
               "--fps", str(fps), "--size", str(size[0]), str(size[1])]
        if quiet:
            cmd.append("--quiet")
        proc = subprocess.run(cmd, env=env, stderr=subprocess.PIPE, text=True)
        if proc.returncode == 0 and out_path.is_file():
            return backend
        if not quiet:
            last = (proc.stderr or "").strip().splitlines()[-1:] or ["no output"]
            print(f"render: {backend} unavailable ({last[0]})", file=sys.stderr)
    return None


def _render(log_path: Path, out_path: Path, fps: float, size: tuple[int, int], quiet: bool) -> None:
    import imageio.v2 as imageio
    import mujoco
    import numpy as np
    from tqdm import tqdm

    from g1_control.robot import description

    log = np.load(log_path)
    t, pos, quat, q = log["t_s"], log["base_pos_m"], log["base_quat_wxyz"], log["q_rad"]
    if len(t) == 0 or np.isnan(pos).all():
        raise SystemExit("log has no ground-truth base pose to replay")
    model = description.mujoco_model()
    data = mujoco.MjData(model)
    renderer = mujoco.Renderer(model, height=size[1], width=size[0])
    camera = mujoco.MjvCamera()
    camera.type = mujoco.mjtCamera.mjCAMERA_TRACKING
    camera.trackbodyid = model.body("pelvis").id
    camera.distance, camera.elevation, camera.azimuth = 3.0, -15.0, 135.0
    frame_times = np.arange(t[0], t[-1], 1.0 / fps)
    idx = np.searchsorted(t, frame_times).clip(0, len(t) - 1)
    try:
        with imageio.get_writer(out_path, fps=fps, codec="libx264", quality=7, macro_block_size=8) as writer:
            for i in tqdm(idx, desc="render", unit="frame", disable=quiet):
                data.qpos[:3], data.qpos[3:7], data.qpos[7:] = pos[i], quat[i], q[i]
                mujoco.mj_forward(model, data)  # also the subtree CoM the tracking camera follows
                renderer.update_scene(data, camera)
                writer.append_data(renderer.render())
    finally:
        renderer.close()  # before interpreter exit, or its destructor complains noisily


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description="Render a g1-control run log (log.npz) to MP4, headless.")
    parser.add_argument("log", type=Path)
    parser.add_argument("out", type=Path)
    parser.add_argument("--fps", type=float, default=10.0)
    parser.add_argument("--size", type=int, nargs=2, default=(480, 360), metavar=("W", "H"))
    parser.add_argument("--quiet", action="store_true")
    args = parser.parse_args(argv)
    _render(args.log, args.out, args.fps, tuple(args.size), args.quiet)
    return 0


if __name__ == "__main__":
    sys.exit(main())
