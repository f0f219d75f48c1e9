"""The run folder, written as the run goes: `g1 launch` and `g1 deploy` alike.

    folder = RunFolder.create(out_root, launch)
    folder.attach(loop)                 # the loop's per-tick log now streams into folder/log/
    ...                                 # run; folder.event({...}) for anything else worth keeping
    log = folder.close_log(loop)        # the whole log, read back (the run's figures come from it)
    folder.write_npz(log)               # log.npz
    folder.finish("completed", "duration reached", summary)   # summary.json

Layout (documented for users in the README, "The run folder"):

    <name>-<YYYYmmdd-HHMMSS>/
      launch.yaml     the validated launch file as run
      summary.json    {"status": "running"} until the run closes; then status (completed,
                      interrupted, fault, error), end_reason, and the run's figures
      events.jsonl    one JSON object per line, flushed as it happens: safety events, loop
                      events, the deploy state machine's transitions
      log/            the per-tick log while the run goes: fields.json (names, dtypes, widths,
                      units, rate, joint and style names) and one raw little-endian file per field,
                      appended and flushed every `flush_every_s`; `read_log(run_dir)` reads it
                      back (whole rows only, so a killed run's log still reads)
      log.npz         the same log assembled at close (what the plot and video readers take),
                      plus joint_names

Memory stays bounded however long the run: the loop keeps one chunk of `flush_every_s` of ticks
and hands it to a writer thread when full.
"""

from __future__ import annotations

import contextlib
import dataclasses
import json
import os
import queue
import signal
import threading
import time
from pathlib import Path
from typing import BinaryIO

import numpy as np
import yaml

from g1_control.robot import g1

LOG_FIELDS: dict[str, tuple[str, str]] = {
    "t_s": ("s", "control time at the tick: simulated time (g1 launch) or ticks x period since the loop started "
            "(g1 deploy)"),
    "command": ("m/s, m/s, rad/s", "operator command (vx, vy, wz) after the safety layer's input vetting"),
    "policy_command": ("m/s, m/s, rad/s", "command given to the walking policy, after velocity correction"),
    "velocity_est": ("m/s, m/s, rad/s", "state estimator's base velocity (vx, vy, wz) in the heading frame"),
    "velocity_true": ("m/s, m/s, rad/s", "ground-truth base velocity in the heading frame (NaN on a robot)"),
    "base_pos_m": ("m", "ground-truth pelvis position in the world (NaN on a robot)"),
    "base_quat_wxyz": ("1", "IMU orientation quaternion (w, x, y, z)"),
    "yaw_rad": ("rad", "heading from the IMU"),
    "tilt_rad": ("rad", "angle between the pelvis z axis and vertical"),
    "q_rad": ("rad", "measured joint positions, G1 joint order (joint_names)"),
    "q_target_rad": ("rad", "joint position targets sent (after the safety filter), joint order"),
    "q_ref_rad": ("rad", "the tracker's reference posture (the plan after the IK), joint order"),
    "ref_root_pos_m": ("m", "the tracker's reference root (pelvis) position in the plan's world frame"),
    "ref_root_quat_wxyz": ("1", "the tracker's reference root orientation (w, x, y, z)"),
    "tau_nm": ("N m", "measured (estimated) joint torques, joint order"),
    "style_id": ("1", "index into style_names of the operator's style (-1 before the first tick)"),
}
"""Per-tick log fields: unit and meaning (one row per tracker tick, at rates.tracker_hz)."""


def _unique_dir(out_root: Path, name: str) -> Path:
    stamp = time.strftime("%Y%m%d-%H%M%S")
    run_dir = out_root / f"{name}-{stamp}"
    suffix = 1
    while run_dir.exists():
        suffix += 1
        run_dir = out_root / f"{name}-{stamp}-{suffix}"
    return run_dir


class RunFolder:
    def __init__(self, run_dir: Path, rate_hz: float, flush_every_s: float = 1.0):
        self.run_dir = Path(run_dir)
        self.log_dir = self.run_dir / "log"
        self.log_dir.mkdir(parents=True, exist_ok=False)
        self.rate_hz = float(rate_hz)
        self.chunk_rows = max(1, round(flush_every_s * rate_hz))
        self.started_monotonic = time.monotonic()
        self.rows = 0
        self.closed = False
        self._files: dict[str, BinaryIO] = {}
        self._dtypes: dict[str, str] = {}
        self._meta: dict = {}
        self._events = open(self.run_dir / "events.jsonl", "a", buffering=1)
        self._queue: queue.Queue = queue.Queue()
        self._error: BaseException | None = None
        self._writer = threading.Thread(target=self._write_loop, name="run-folder-writer", daemon=True)
        self._writer.start()
        self._write_json("summary.json", {"status": "running", "started": time.strftime("%Y-%m-%dT%H:%M:%S%z"),
                                          "pid": os.getpid()})

    @classmethod
    def create(cls, out_root: Path, launch, flush_every_s: float = 1.0) -> RunFolder:
        """A new folder under `out_root` for `launch` (a LaunchFile), with launch.yaml written."""
        folder = cls(_unique_dir(Path(out_root), launch.name), launch.rates.tracker_hz, flush_every_s)
        (folder.run_dir / "launch.yaml").write_text(yaml.safe_dump(dataclasses.asdict(launch), sort_keys=False))
        return folder

    # -- while the run goes ------------------------------------------------------------------------
    def attach(self, loop) -> None:
        """Stream `loop`'s per-tick log and events into this folder (the loop keeps one chunk)."""
        from g1_control.loop.control_loop import RunLog

        loop.log = RunLog(self.chunk_rows, sink=self._queue.put)
        loop.on_record = self.event

    def event(self, record: dict) -> None:
        """Append one event (a JSON object; `t_run_s`, seconds since the folder opened, is added)."""
        if self.closed:
            return
        line = dict(record, t_run_s=round(time.monotonic() - self.started_monotonic, 4))
        self._events.write(json.dumps(line, default=_jsonable) + "\n")

    def _write_loop(self) -> None:
        while True:
            chunk = self._queue.get()
            if chunk is None:
                return
            try:
                self._append(chunk)
            except BaseException as exc:
                self._error = exc

    def _append(self, chunk: dict[str, np.ndarray]) -> None:
        if not self._files:
            self._write_fields(chunk)
        n = len(chunk["t_s"])
        for name, arr in chunk.items():
            f = self._files[name]
            f.write(np.ascontiguousarray(arr, dtype=self._dtypes[name]).tobytes())
            f.flush()
        self.rows += n

    def _write_fields(self, chunk: dict[str, np.ndarray]) -> None:
        self._dtypes = {name: np.dtype(arr.dtype).newbyteorder("<").str for name, arr in chunk.items()}
        fields = {name: {"dtype": self._dtypes[name], "shape": list(arr.shape[1:]),
                         "unit": LOG_FIELDS.get(name, ("", ""))[0], "doc": LOG_FIELDS.get(name, ("", ""))[1],
                         "file": f"{name}.bin"}
                  for name, arr in chunk.items()}
        self._meta = {"rate_hz": self.rate_hz, "rows_per_flush": self.chunk_rows, "joint_names": list(g1.JOINT_NAMES),
                      "style_names": [], "fields": fields}
        (self.log_dir / "fields.json").write_text(json.dumps(self._meta, indent=2))
        for name in chunk:
            self._files[name] = open(self.log_dir / f"{name}.bin", "ab")

    # -- the end -------------------------------------------------------------------------------------
    def close_log(self, loop=None) -> dict[str, np.ndarray]:
        """Flush the loop's last partial chunk, stop the writer and read the whole log back."""
        if loop is not None:
            loop.log.flush()
        if self._writer.is_alive():
            self._queue.put(None)
            self._writer.join()
        for f in self._files.values():
            os.fsync(f.fileno())
            f.close()
        if self._error is not None:
            raise self._error
        if loop is not None and self._files:
            self._meta["style_names"] = list(loop.log.style_names)
            (self.log_dir / "fields.json").write_text(json.dumps(self._meta, indent=2))
        return read_log(self.run_dir)

    def write_npz(self, log: dict[str, np.ndarray]) -> Path:
        """log.npz: the whole log in one file (the plot and video readers take it), with joint_names."""
        path = self.run_dir / "log.npz"
        # numpy's stub has a keyword `allow_pickle: bool` that mypy matches against **dict[str, ndarray].
        np.savez_compressed(path, joint_names=np.array(g1.JOINT_NAMES), **log)  # type: ignore[arg-type]
        return path

    def finish(self, status: str, end_reason: str, summary: dict) -> None:
        """The final summary.json (status: completed, interrupted, fault, error); the events file closes."""
        self._write_json("summary.json", {"status": status, "end_reason": end_reason,
                                          "run_dir": str(self.run_dir), "ticks_logged": self.rows, **summary})
        if not self.closed:
            self.closed = True
            self._events.close()

    def _write_json(self, name: str, data: dict) -> None:
        tmp = self.run_dir / f".{name}.tmp"
        tmp.write_text(json.dumps(data, indent=2, default=_jsonable))
        os.replace(tmp, self.run_dir / name)  # never a half-written summary


@contextlib.contextmanager
def interrupt_on_signals(signals=(signal.SIGINT, signal.SIGTERM)):
    """Inside: SIGINT and SIGTERM raise Interrupted(signum) (a KeyboardInterrupt) in the main thread,
    so a run unwinds through its finally blocks and closes its run folder. Elsewhere: a no-op."""
    from g1_control.errors import Interrupted

    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def handler(signum, frame):
        raise Interrupted(signum)

    previous = {sig: signal.signal(sig, handler) for sig in signals}
    try:
        yield
    finally:
        for sig, old in previous.items():
            signal.signal(sig, old)


def _jsonable(value):
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, (np.floating, np.integer)):
        return value.item()
    if isinstance(value, Path):
        return str(value)
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return dataclasses.asdict(value)
    return str(value)


def read_log(run_dir: str | Path) -> dict[str, np.ndarray]:
    """The per-tick log of a run folder: log.npz when the run closed, else the streamed log/ files
    (whole rows only: a run killed mid-write still reads)."""
    run_dir = Path(run_dir)
    meta_path = run_dir / "log" / "fields.json"
    if not meta_path.is_file():
        npz = run_dir / "log.npz"
        if npz.is_file():
            with np.load(npz) as data:
                return {k: data[k] for k in data.files if k != "joint_names"}
        return {name: np.zeros((0,)) for name in LOG_FIELDS} | {"style_names": np.array([], dtype=str)}
    meta = json.loads(meta_path.read_text())
    arrays: dict[str, np.ndarray] = {}
    for name, spec in meta["fields"].items():
        width = int(np.prod(spec["shape"])) if spec["shape"] else 1
        flat = np.fromfile(run_dir / "log" / spec["file"], dtype=spec["dtype"])
        rows = flat.size // width
        arrays[name] = flat[: rows * width].reshape((rows, *spec["shape"]))
    n = min(len(a) for a in arrays.values())
    out = {name: a[:n] for name, a in arrays.items()}
    out["style_names"] = np.array(meta.get("style_names", []), dtype=str)
    return out
