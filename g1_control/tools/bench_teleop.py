"""`g1 bench teleop`: latency from an input event written to a device's file descriptor to the
changed Command that poll() returns, against a bare os.read of the same bytes on the same fd.

A writer process and this reader play ping-pong: the writer timestamps (CLOCK_MONOTONIC, shared
by both processes) and writes one event, the reader waits for it, records when it saw it and
acknowledges; the writer pauses 0.2-1 ms at random (up to a loop period in the 100 Hz phase) and writes the next. Baseline and device
samples alternate on the same fd, so load from other jobs hits both alike. Phases:

  gamepad, pipe:      evdev frames through a FIFO; baseline os.read | EvdevGamepad.poll()
  keyboard, pty:      key bytes through a pseudo-terminal; baseline os.read | TerminalKeyboard.poll()
  gamepad, 100 Hz:    as the first, but read/poll only on the ticks of a 100 Hz loop (what the
                      control loop adds: up to one input period)
  remote, in-process: 40 remote bytes; baseline struct unpack | UnitreeRemote.feed()+poll()
"""

from __future__ import annotations

import array
import json
import os
import random
import select
import struct
import tempfile
import time
from collections.abc import Callable

import numpy as np
from tqdm import tqdm

from g1_control.teleop import evdev_protocol as ev
from g1_control.teleop.gamepad import EvdevGamepad
from g1_control.teleop.keyboard import TerminalKeyboard
from g1_control.teleop.layouts import LAYOUTS
from g1_control.teleop.mapping import MappingConfig
from g1_control.teleop.unitree_remote import UnitreeRemote, encode_wireless_remote

_NS = time.perf_counter_ns  # CLOCK_MONOTONIC on Linux: comparable across processes


def _no_slew(kind: str) -> MappingConfig:
    # Slew would spread one event over several polls; the benchmark times the first change.
    return MappingConfig.from_dict({"slew_rate": {"vx": None, "vy": None, "wz": None}}, "bench", layout=LAYOUTS[kind])


def _gamepad_payload(i: int) -> bytes:
    # Consecutive values differ, and so do values two apart (baseline and device alternate).
    return ev.pack_event(ev.EV_ABS, ev.ABS_Y, -32768 + (i % 50) * 300) + ev.syn_report()


def _keyboard_payload(i: int) -> bytes:
    # Device samples are the odd ones; w, s, w, s keeps vx moving inside its range.
    return b"w" if (i // 2) % 2 == 0 else b"s"


def _writer(write_fd: int, ack_fd: int, result_path: str, payload: Callable[[int], bytes], max_gap_s: float) -> None:
    times = array.array("q")
    rng = random.Random(1)
    i = 0
    while True:
        data = payload(i)
        times.append(_NS())
        os.write(write_fd, data)
        if os.read(ack_fd, 1) != b"k":
            break
        i += 1
        time.sleep(rng.uniform(0.0002, max_gap_s))
    with open(result_path, "wb") as fh:
        fh.write(times.tobytes())


def _ping_pong(write_fd: int, read_fd: int, payload: Callable[[int], bytes], wait_baseline, wait_device,
               seconds: float, bar: tqdm, max_gap_s: float = 0.001) -> tuple[np.ndarray, np.ndarray]:
    """Run writer/reader for `seconds`; returns latencies in us (baseline, device).

    max_gap_s: the writer's longest random pause; a full loop period in the loop phase, so events
    land at every phase of the loop's tick as an operator's would."""
    ack_r, ack_w = os.pipe()
    result_fd, result_path = tempfile.mkstemp(prefix="g1_teleop_bench_")
    os.close(result_fd)
    pid = os.fork()
    if pid == 0:  # the writer: only os calls, then leave without running the parent's cleanup
        try:
            os.close(ack_w)
            _writer(write_fd, ack_r, result_path, payload, max_gap_s)
        finally:
            os._exit(0)
    os.close(ack_r)
    seen = []
    deadline = time.monotonic() + seconds
    i = 0
    try:
        while True:
            (wait_baseline if i % 2 == 0 else wait_device)(read_fd)
            seen.append(_NS())
            i += 1
            bar.update(1)
            if time.monotonic() > deadline:
                os.write(ack_w, b"q")
                break
            os.write(ack_w, b"k")
        os.waitpid(pid, 0)
        with open(result_path, "rb") as fh:
            written = np.frombuffer(fh.read(), dtype=np.int64)
    finally:
        os.close(ack_w)
        os.unlink(result_path)
    lat_us = (np.asarray(seen, dtype=np.int64) - written[: len(seen)]) / 1e3
    return lat_us[0::2], lat_us[1::2]


def _waiters(device, tick_s: float | None):
    """(baseline, device) functions that return once the next event has been seen."""

    def wait(fd: int) -> None:
        if tick_s is None:
            select.select([fd], [], [], 5.0)

    def tick() -> None:
        assert tick_s is not None  # called only when ticking
        now = time.monotonic()
        time.sleep(tick_s - now % tick_s)

    def baseline(fd: int) -> None:
        while True:
            if tick_s is None:
                wait(fd)
            else:
                tick()
            if select.select([fd], [], [], 0)[0] and os.read(fd, 4096):
                return

    last = [device.poll()]

    def through_device(fd: int) -> None:
        while True:
            if tick_s is None:
                wait(fd)
            else:
                tick()
            command = device.poll()
            if command != last[0]:
                last[0] = command
                return
            if device.lost:
                raise RuntimeError(f"device lost during the benchmark: {device.lost_reason}")

    return baseline, through_device


def _remote_phase(seconds: float, bar: tqdm) -> tuple[np.ndarray, np.ndarray]:
    remote = UnitreeRemote(_no_slew("unitree_remote"), stale_after_s=60.0)
    packets = [encode_wireless_remote(ly=-1.0 + (i % 50) * 0.04) for i in range(50)]
    unpack = struct.Struct("<2sH5f16s").unpack
    base, dev = [], []
    deadline = time.monotonic() + seconds
    i = 0
    while time.monotonic() < deadline:
        data = packets[i % 50]
        t0 = _NS()
        unpack(data)
        t1 = _NS()
        remote.feed(data)
        remote.poll()
        t2 = _NS()
        base.append((t1 - t0) / 1e3)
        dev.append((t2 - t1) / 1e3)
        i += 1
        if i % 1000 == 0:
            bar.update(1000)
    return np.asarray(base), np.asarray(dev)


def _stats(lat_us: np.ndarray) -> dict:
    return {"n": int(lat_us.size), "p50_us": float(np.percentile(lat_us, 50)),
            "p99_us": float(np.percentile(lat_us, 99)), "max_us": float(lat_us.max())}


def main(args) -> int:
    tqdm.monitor_interval = 0  # no tqdm monitor thread: this benchmark forks
    seconds = max(1.0, float(args.seconds))
    per_phase = seconds / 4
    results = {}
    with tempfile.TemporaryDirectory(prefix="g1_teleop_bench_") as tmp, \
            tqdm(desc="teleop latency", unit=" events") as bar:
        fifo = os.path.join(tmp, "event0")
        os.mkfifo(fifo)
        for name, tick_s in (("gamepad, pipe", None), ("gamepad, 100 Hz loop", 0.01)):
            pad = EvdevGamepad(fifo, _no_slew("gamepad"))
            write_fd = os.open(fifo, os.O_WRONLY)
            try:
                base, through = _waiters(pad, tick_s)
                results[name] = _ping_pong(write_fd, pad.fileno(), _gamepad_payload, base, through, per_phase, bar,
                                           max_gap_s=tick_s or 0.001)
            finally:
                os.close(write_fd)
                pad.close()

        master, slave = os.openpty()
        keyboard = TerminalKeyboard(_no_slew("keyboard"), fd=slave)
        try:
            base, through = _waiters(keyboard, None)
            results["keyboard, pty"] = _ping_pong(master, slave, _keyboard_payload, base, through, per_phase, bar)
        finally:
            keyboard.close()
            os.close(master)
            os.close(slave)
        results["remote, in-process"] = _remote_phase(per_phase, bar)

    figures = {}
    print(f"\nteleop input latency: event written -> changed Command from poll() ({os.cpu_count()} CPUs, "
          f"{seconds:.0f} s)")
    print(f"{'phase':22s} {'path':9s} {'n':>6s} {'p50 us':>9s} {'p99 us':>9s} {'max us':>9s}")
    for name, (base, dev) in results.items():
        b, d = _stats(base), _stats(dev)
        figures[name] = {"baseline": b, "device": d, "p50_ratio": d["p50_us"] / b["p50_us"],
                         "p99_ratio": d["p99_us"] / b["p99_us"], "p50_overhead_us": d["p50_us"] - b["p50_us"]}
        for label, s in (("baseline", b), ("device", d)):
            print(f"{name:22s} {label:9s} {s['n']:6d} {s['p50_us']:9.1f} {s['p99_us']:9.1f} {s['max_us']:9.1f}")
        print(f"{'':22s} {'ratio':9s} {'':6s} {figures[name]['p50_ratio']:8.2f}x {figures[name]['p99_ratio']:8.2f}x"
              f"   (p50 overhead {figures[name]['p50_overhead_us']:+.1f} us)")
    print("baseline: os.read of the same bytes on the same fd (remote: struct unpack of the same 40 bytes)")
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(figures, fh, indent=2)
    return 0
