"""The public Python API of g1-control (docs/api.md); `from g1_control import ...` gives the same names.

What is here keeps its signature; everything else in the package is internal and may move.

    import g1_control as g1c

    launch = g1c.load_launch("sim_walk", overrides=["duration_s=5"])
    loop = g1c.build_loop(launch)            # the one builder g1 launch and g1 deploy use
    loop.reset()
    loop.run(5.0)                            # lockstep MuJoCo, faster than real time
    log = loop.log.arrays()                  # per-tick numpy arrays (see read_run for the names)

Runs, clips and the IK:

    result = g1c.run(launch, out="runs")     # what g1 launch does: summary + run folder
    rec = g1c.read_run(result.run_dir)       # rec.log (numpy), rec.dataframe() (pandas), rec.summary
    clip = g1c.retarget("walk.bvh")          # human mocap -> G1 MotionClip (pinocchio IK)
    ik = g1c.IKRetargeter(g1c.IKConfig())    # the differential-IK QP alone: ik.solve(reference, q)
"""

from __future__ import annotations

import json
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from g1_control.errors import G1ControlError
from g1_control.ik.retargeter import IKConfig, IKRetargeter
from g1_control.interfaces import Backend, Generator, InputDevice, Retargeter, Tracker
from g1_control.launch.builder import build_loop
from g1_control.launch.schema import LaunchFile
from g1_control.loop.control_loop import ControlLoop
from g1_control.motion.clip import MotionClip
from g1_control.motion.human import HumanMotion
from g1_control.report.results import RunResult
from g1_control.robot import g1
from g1_control.types import Command, EstimatedState, JointReference, KinematicReference, MotorCommand, RobotState

__all__ = [
    "Backend", "Command", "CommandInput", "ControlLoop", "EstimatedState", "G1ControlError", "Generator",
    "HumanMotion", "IKConfig", "IKRetargeter", "InputDevice", "JointReference", "KinematicReference",
    "LaunchFile", "MotionClip", "MotorCommand", "Retargeter", "RobotState", "RunRecord", "RunResult", "Tracker",
    "build_loop", "g1", "launch_files", "load_clip", "load_launch", "read_run", "retarget", "run", "save_clip",
]


def load_launch(file: str | Path, overrides: Iterable[str] = ()) -> LaunchFile:
    """A validated launch file: a path, or the name of a shipped one (`sim_walk`; see launch_files()).

    overrides: dotted `KEY=VALUE` settings, as `g1 launch --set` takes them (`tracker.policy=...`).
    """
    from g1_control.launch.schema import load_launch as _load
    from g1_control.resources import resolve_launch

    path, _ = resolve_launch(file)
    return _load(path, overrides=list(overrides))


def launch_files() -> dict[str, Path]:
    """The launch files that come with g1-control, by name."""
    from g1_control.resources import launch_files as _files

    return _files()


def run(launch: LaunchFile, *, out: str | Path | None = None, video: bool = False,
        progress: bool = False) -> RunResult:
    """Run `launch` in simulation to its end (or a fall), as `g1 launch` does; with `out`, write a
    run folder under it (result.run_dir) that read_run() and `g1 replay` read."""
    from g1_control.launch.runner import run as _run

    return _run(launch, out_root=Path(out) if out is not None else None, video=video, progress=progress)


class CommandInput(InputDevice):
    """An input device driven from code: `inp.set(vx_mps=0.5)`, or a schedule `f(now_s) -> Command`.

    Hand it to build_loop(launch, input_device=inp); the loop polls it at the input rate.
    """

    name = "code"

    def __init__(self, schedule: Callable[[float], Command] | None = None):
        self.schedule = schedule
        self.command = Command()

    def set(self, vx_mps: float = 0.0, vy_mps: float = 0.0, wz_radps: float = 0.0, **fields) -> None:
        """The command from now on (other Command fields, e.g. style='arms_up', by keyword)."""
        self.command = Command(vx_mps=vx_mps, vy_mps=vy_mps, wz_radps=wz_radps, **fields).validate()

    def poll(self, now_s: float) -> Command:
        return self.schedule(now_s) if self.schedule is not None else self.command


def load_clip(path: str | Path) -> MotionClip | HumanMotion:
    """A motion file: G1 clips (.npz: motion library / BeyondMimic; .csv: Unitree) as MotionClip,
    human mocap (.npy joint positions, .pt OMOMO, .bvh) as HumanMotion."""
    from g1_control.motion.formats.dispatch import load_motion

    return load_motion(path)


def save_clip(clip: MotionClip, path: str | Path) -> None:
    """Write a clip as .npz (the motion-library format) or .csv (Unitree's)."""
    from g1_control.motion.formats.dispatch import save_clip as _save

    _save(clip, path)


def retarget(motion: str | Path | HumanMotion, *, fps: float = 50.0,
             progress: Callable[[int], None] | None = None) -> MotionClip:
    """Human motion capture (a file or a HumanMotion) to a G1 MotionClip with the pinocchio IK, as
    `g1 retarget` does with its defaults. A G1 clip file is returned as it is."""
    from g1_control.motion.resample import resample
    from g1_control.retarget.mocap import MocapRetargetConfig, MocapRetargeter

    if not isinstance(motion, HumanMotion):
        loaded = load_clip(motion)
        if isinstance(loaded, MotionClip):
            return loaded if loaded.fps == fps else resample(loaded, fps)
        motion = loaded
    return MocapRetargeter(MocapRetargetConfig(fps=fps)).retarget(motion, progress=progress)


@dataclass
class RunRecord:
    """A run folder read back: `log` holds per-tracker-tick numpy arrays, `summary` the summary.json
    (segments, events, timings), `launch` the launch file as run.

    Log arrays: t_s (N,); command, policy_command, velocity_est, velocity_true (N, 3: vx, vy, wz in
    the heading frame; velocity_true is NaN on a robot); base_pos_m (N, 3); base_quat_wxyz (N, 4);
    yaw_rad, tilt_rad (N,); q_rad, q_target_rad, tau_nm (N, 29) in g1.JOINT_NAMES order.
    """

    path: Path
    log: dict[str, np.ndarray]
    summary: dict
    launch: dict

    def dataframe(self):
        """The log as a pandas DataFrame, one row per tick, indexed by t_s; columns such as
        command_vx, velocity_true_wz, base_pos_z, q_left_knee_joint (needs pandas)."""
        try:
            import pandas as pd
        except ImportError:
            raise G1ControlError("RunRecord.dataframe needs pandas (pip install pandas); rec.log has numpy arrays") from None
        axes = {3: ("vx", "vy", "wz"), 4: ("w", "x", "y", "z")}
        columns: dict[str, np.ndarray] = {}
        n = len(self.log["t_s"])
        for name, arr in self.log.items():
            if name == "t_s" or arr.ndim == 0 or len(arr) != n:
                continue  # not per tick (joint_names, style_names)
            if arr.ndim == 1:
                columns[name] = arr
                continue
            if arr.shape[1] == g1.NUM_JOINTS:
                prefix = name.removesuffix("_rad").removesuffix("_nm")
                labels = [f"{prefix}_{j}" for j in g1.JOINT_NAMES]
            elif name.startswith("base_pos"):
                labels = [f"base_pos_{a}" for a in "xyz"]
            elif name.startswith("base_quat"):
                labels = [f"base_quat_{a}" for a in axes[4]]
            else:
                labels = [f"{name}_{a}" for a in axes.get(arr.shape[1], range(arr.shape[1]))]
            columns.update({label: arr[:, k] for k, label in enumerate(labels)})
        return pd.DataFrame(columns, index=pd.Index(self.log["t_s"], name="t_s"))


def read_run(path: str | Path) -> RunRecord:
    """A run folder written by `g1 launch` / run(out=...) (or its log.npz)."""
    import yaml

    path = Path(path)
    folder = path if path.is_dir() else path.parent
    if not (folder / "log.npz").is_file():
        raise G1ControlError(f"{folder}: no log.npz; a run folder is what g1 launch writes (runs/NAME-TIME)")
    with np.load(folder / "log.npz") as data:
        log = {k: data[k] for k in data.files}
    summary = json.loads((folder / "summary.json").read_text()) if (folder / "summary.json").is_file() else {}
    launch = yaml.safe_load((folder / "launch.yaml").read_text()) if (folder / "launch.yaml").is_file() else {}
    return RunRecord(folder, log, summary, launch or {})
