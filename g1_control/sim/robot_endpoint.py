"""The robot's end of a link: what the G1's firmware does with LowCmd_/LowState_, around any
physics Backend (MockG1 here; the MuJoCo backend for `g1 sim-robot`).

Like the robot: LowState_ goes out at a fixed rate with a valid CRC and a running tick; a LowCmd_
with a bad CRC or a mode_machine other than the robot's is dropped without a word; a motor slot
whose mode is not 1 produces no torque; with no valid command yet, every motor is off.
Fault switches (publish, freeze_state, corrupt_state_crc, corrupt_next_states) let tests break the stream on purpose.

    python -m g1_control.sim.robot_endpoint --interface lo --domain 1 --seconds 5
"""

from __future__ import annotations

import argparse
import json
import sys
import threading
import time
from collections import deque
from dataclasses import asdict, dataclass

import numpy as np

from g1_control.errors import CrcMismatchError, MalformedMessageError
from g1_control.hardware.links.base import Link
from g1_control.hardware.unitree.conversions import lowcmd_to_motor_command, robot_state_to_lowstate
from g1_control.hardware.unitree.messages import LowCmd
from g1_control.interfaces import Backend
from g1_control.robot import g1
from g1_control.types import MotorCommand

PERIOD_BIN_S = 1e-5
PERIOD_BINS = 20_000
"""LowCmd_ period histogram: 10 us bins up to 200 ms."""


@dataclass
class EndpointCounters:
    states_sent: int = 0
    commands_applied: int = 0
    bad_crc: int = 0
    malformed: int = 0
    wrong_mode_machine: int = 0
    damping_commands: int = 0
    """Valid commands with every enabled motor at kp 0 and kd > 0."""
    ignored_while_builtin_active: int = 0
    """Valid commands dropped because the robot's own controller still held the motors."""


class RobotEndpoint:
    def __init__(self, link: Link, physics: Backend, rate_hz: float = 500.0):
        if link.side != "robot":
            raise ValueError("RobotEndpoint needs the robot side of a link")
        self.link, self.physics = link, physics
        self.period_s = 1.0 / rate_hz
        self.counters = EndpointCounters()
        self.last_command: LowCmd | None = None
        self.last_command_time_s = float("nan")
        self.first_damping_time_s = float("nan")
        """time.monotonic() of the first damping command applied since the last mark_faults_clear()."""
        self.first_damping_base_pos_w_m: list[float] | None = None
        """Simulated base position when that damping command arrived (None on MockG1)."""
        self.command_times: deque[float] = deque(maxlen=60_000)
        """time.monotonic() of every valid LowCmd_ taken off the link (two minutes at 500 Hz)."""
        self.period_histogram = np.zeros(PERIOD_BINS + 1, dtype=np.int64)
        """Every LowCmd_ period since start, in PERIOD_BIN_S bins (the last bin: longer), for whole-run percentiles."""
        self._timing_lock = threading.Lock()
        """Held while command_times/period_histogram change and while a report copies them: reports run on
        another thread (the emulator's stdin server) and must never see them half-updated."""
        self.builtin_active = False
        """While True (the built-in controller runs), valid commands are ignored, as on the robot, and
        the physics is paused at its standing pose (Unitree's controller itself is not emulated)."""
        self.publish = True
        self.freeze_state = False
        self.corrupt_state_crc = False
        self.unset_state_fields = False
        """As Unitree's MuJoCo simulator (g1_control/sim/unitree_mujoco.py): LowState_ with crc, tick and
        mode_machine left at 0, and every LowCmd_ taken whatever its CRC and mode_machine."""
        self.corrupt_next_states = 0
        """The next this many states carry a wrong CRC (a burst), counted down as they go out."""
        self._frozen: bytes | None = None
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        self._tick = 0
        physics.write_command(MotorCommand(enable=np.zeros(g1.NUM_JOINTS, dtype=bool)))

    def start(self) -> RobotEndpoint:
        self._thread = threading.Thread(target=self.run, name="robot-endpoint", daemon=True)
        self._thread.start()
        return self

    def stop(self) -> None:
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout=10.0)  # a busy host: the link is closed only after the thread is out

    def run(self, seconds: float | None = None) -> EndpointCounters:
        end = time.monotonic() + seconds if seconds is not None else float("inf")
        next_t = time.monotonic()
        while not self._stop.is_set() and time.monotonic() < end:
            self._apply_commands(self.link.receive(0.0))
            if self.physics.lockstep and not self.builtin_active:
                self.physics.step(self.period_s)
            self._publish_state()
            next_t += self.period_s
            delay = next_t - time.monotonic()
            if delay > 0:
                # Wait on the link, not on a clock: commands are applied as soon as they arrive.
                self._apply_commands(self.link.receive(delay))
                remaining = next_t - time.monotonic()
                if remaining > 0:
                    self._stop.wait(remaining)
            elif delay < -0.1:
                next_t = time.monotonic()
        return self.counters

    def _apply_commands(self, payloads: list[bytes]) -> None:
        for payload in payloads:
            try:
                msg = self.link.decode_command(payload, verify=not self.unset_state_fields)
            except CrcMismatchError:
                self.counters.bad_crc += 1
                continue
            except MalformedMessageError:
                self.counters.malformed += 1
                continue
            self._record_command_time(time.monotonic())
            state = self.physics.read_state()
            if msg.mode_machine != state.mode_machine and not self.unset_state_fields:
                self.counters.wrong_mode_machine += 1
                continue
            if self.builtin_active:
                self.counters.ignored_while_builtin_active += 1
                continue
            command = lowcmd_to_motor_command(msg)
            if command.enable.any() and np.all(command.kp[command.enable] == 0) \
                    and np.all(command.kd[command.enable] > 0):
                self.counters.damping_commands += 1
                if self.first_damping_time_s != self.first_damping_time_s:  # still NaN
                    self.first_damping_time_s = time.monotonic()
                    pos = state.base_pos_w_m
                    self.first_damping_base_pos_w_m = None if pos is None else [float(v) for v in pos]
            self.physics.write_command(command)
            self.last_command = msg
            self.last_command_time_s = time.monotonic()
            self.counters.commands_applied += 1

    def _record_command_time(self, now: float) -> None:
        """Add one valid LowCmd_ arrival (time.monotonic()) to the period record."""
        with self._timing_lock:
            if self.command_times:
                self.period_histogram[min(int((now - self.command_times[-1]) / PERIOD_BIN_S), PERIOD_BINS)] += 1
            self.command_times.append(now)

    def command_wire_stats(self, window_s: float | None = None) -> dict:
        """Rate and period percentiles of the LowCmd_ stream as this end took it off the link (the
        robot's view of the host's 500 Hz stream: sender jitter + transport + this loop's wake-ups)."""
        with self._timing_lock:
            times = np.array(self.command_times)
        if window_s is not None and times.size:
            times = times[times >= times[-1] - window_s]
        if times.size < 3:
            return {"lowcmd_count": int(times.size)}
        periods = np.diff(times)
        p50, p99 = np.percentile(periods, [50, 99])
        return {"lowcmd_count": int(times.size), "lowcmd_rate_hz": float((times.size - 1) / (times[-1] - times[0])),
                "lowcmd_period_p50_ms": float(p50 * 1e3), "lowcmd_period_p99_ms": float(p99 * 1e3),
                "lowcmd_period_max_ms": float(periods.max() * 1e3), "lowcmd_window_s": float(times[-1] - times[0])}

    def whole_run_period_stats(self) -> dict:
        """LowCmd_ period percentiles over every command since start (from the histogram, to PERIOD_BIN_S)."""
        with self._timing_lock:
            hist = self.period_histogram.copy()
        n = int(hist.sum())
        if n == 0:
            return {"lowcmd_periods": 0}
        cum = np.cumsum(hist)

        def pct(p: float) -> float:
            return float((np.searchsorted(cum, p / 100 * n) + 0.5) * PERIOD_BIN_S * 1e3)

        top = int(np.nonzero(hist)[0][-1])
        return {"lowcmd_periods": n, "lowcmd_period_all_p50_ms": pct(50), "lowcmd_period_all_p99_ms": pct(99),
                "lowcmd_period_all_p999_ms": pct(99.9),
                "lowcmd_period_all_max_ms": float((top + 1) * PERIOD_BIN_S * 1e3) if top < PERIOD_BINS else float("inf"),
                "lowcmd_periods_over_10ms": int(hist[int(0.010 / PERIOD_BIN_S):].sum())}

    def mark_faults_clear(self) -> None:
        """Clear every fault switch and forget the last damping time (start of a fault trial)."""
        self.publish, self.freeze_state, self.corrupt_state_crc = True, False, False
        self.corrupt_next_states = 0
        self.first_damping_time_s = float("nan")

    def _publish_state(self) -> None:
        if not self.publish:
            return
        if self.freeze_state and self._frozen is not None:
            payload = self._frozen
        else:
            state = self.physics.read_state()
            state.tick = self._tick
            msg = robot_state_to_lowstate(state)
            if self.unset_state_fields:
                msg.tick = msg.mode_machine = 0
            payload = self.link.encode(msg)
            if self.unset_state_fields:
                payload = payload[:-4] + bytes(4)  # the CRC word ends both wire forms: crc 0
            burst = self.corrupt_next_states > 0
            if burst:
                self.corrupt_next_states -= 1
            if self.corrupt_state_crc or burst:
                # Flip one bit of the last byte, which lies inside the CRC word on both wire forms.
                payload = payload[:-1] + bytes([payload[-1] ^ 0x01])
            self._frozen = payload
        self.link.send(payload)
        self._tick += 1
        self.counters.states_sent += 1


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        description="Stand in for a G1 on a DDS link (MockG1 motors, robot-side protocol rules); "
        "prints its counters as JSON when done. For tests and transport checks; the MuJoCo emulator "
        "is `g1 sim-robot`.")
    parser.add_argument("--interface", required=True, help="network interface to bind ('lo' for tests)")
    parser.add_argument("--domain", type=int, default=1, help="DDS domain id (default 1, simulation)")
    parser.add_argument("--partition", default=None, help="DDS partition (isolates concurrent test runs)")
    parser.add_argument("--seconds", type=float, default=5.0, help="how long to run")
    parser.add_argument("--mode-machine", type=int, default=5, help="variant to report (4, 5 or 6)")
    parser.add_argument("--motion-service", default="ai",
                        help="name of the built-in controller the emulated motion service reports active")
    args = parser.parse_args(argv)

    from g1_control.hardware.links.dds import DdsLink
    from g1_control.hardware.unitree.motion_service import MotionServiceEmulator
    from g1_control.sim.mock_robot import MockG1

    link = DdsLink("robot", args.interface, args.domain, partition=args.partition)
    service = MotionServiceEmulator(link._participant, args.partition, active_mode=args.motion_service)
    endpoint = RobotEndpoint(link, MockG1(mode_machine=args.mode_machine))
    counters = endpoint.run(args.seconds)
    service.close()
    report = asdict(counters)
    report["motion_service_calls"] = service.calls
    report["motion_service_mode"] = service.active_mode
    last = endpoint.last_command
    report["last_mode_machine"] = None if last is None else last.mode_machine
    report["last_kp"] = None if last is None else [float(v) for v in last.motor_kp_nm_per_rad[:29]]
    print(json.dumps(report), flush=True)
    link.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
