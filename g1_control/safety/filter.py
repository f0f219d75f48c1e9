"""SafetyFilter: vets every MotorCommand before a backend sees it.

Until it trips, commands are clamped to the G1's joint position, velocity and torque limits and to
sane gains (every clamp counted per joint). The robot's state is validated as a whole every tick:
finite everywhere, joints within their limits (give or take state_limit_margin_rad), a unit IMU
quaternion, the mode_machine accepted at the start (`expect_mode_machine`; else the first one
seen), a tick that advances. It trips on the first of: an invalid state, stale state, a burst of
bad CRCs, a second publisher on the link, tilt (fall), joint over-speed, NaN/inf in a command,
repeated deadline overruns, lost operator input, an over-temperature motor, an IK that finds no
solution for longer than ik_hold_ticks tracker ticks in a row, or an e-stop; from
then on it returns the damping command (kp 0, kd > 0) for good. A new filter is the only way back: resuming control is an operator
decision the deploy state machine makes, never this layer.

All times (`now_s`, RobotState.t_s) are one clock: the backend's receive clock on the robot
(time.monotonic), simulation time in lockstep.
"""

from __future__ import annotations

import logging
import math
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass, field, replace

import numpy as np

from g1_control.robot import g1
from g1_control.rotations import tilt_rad
from g1_control.safety.config import SafetyConfig
from g1_control.safety.events import SafetyEvent, SafetyEventKind
from g1_control.types import Button, Command, MotorCommand, RobotState

log = logging.getLogger("g1_control.safety")

CLAMPED_FIELDS = ("q_rad", "dq_radps", "tau_nm", "kp", "kd")
STATE_FIELDS = ("q_rad", "dq_radps", "tau_nm", "imu_quat_wxyz", "imu_gyro_radps", "imu_acc_mps2", "motor_temperature_c")
"""The RobotState arrays that must be finite every tick."""
TICK_MODULUS = 1 << 32
"""LowState_.tick is a u32: it wraps."""


def _inside_float32(lower: np.ndarray, upper: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Bounds that stay inside [lower, upper] after the wire's float32 rounding too."""
    lo32, hi32 = lower.astype(np.float32), upper.astype(np.float32)
    lo32 = np.where(lo32 < lower, np.nextafter(lo32, np.float32(np.inf)), lo32)
    hi32 = np.where(hi32 > upper, np.nextafter(hi32, np.float32(-np.inf)), hi32)
    return lo32.astype(np.float64), hi32.astype(np.float64)


@dataclass
class ClampCounts:
    """How many commands had each joint's field clamped."""

    by_field: np.ndarray = field(default_factory=lambda: np.zeros((len(CLAMPED_FIELDS), g1.NUM_JOINTS), dtype=np.int64))
    """Counts per (field in CLAMPED_FIELDS order, joint); per_joint holds views of its rows."""
    per_joint: dict[str, np.ndarray] = field(init=False)
    commands: int = 0
    """Commands that needed at least one clamp."""

    def __post_init__(self) -> None:
        self.per_joint = {name: self.by_field[i] for i, name in enumerate(CLAMPED_FIELDS)}

    @property
    def total(self) -> int:
        return int(sum(int(v.sum()) for v in self.per_joint.values()))




class _Burst:
    """True once `count` events fall within `window_s`."""

    def __init__(self, count: int, window_s: float):
        self.count, self.window_s = int(count), window_s
        self.times: deque[float] = deque(maxlen=int(count))

    def add(self, now_s: float, n: int = 1) -> bool:
        for _ in range(min(n, self.count)):
            self.times.append(now_s)
        return len(self.times) == self.count and now_s - self.times[0] <= self.window_s


class SafetyFilter:
    def __init__(self, config: SafetyConfig | None = None,
                 on_event: Callable[[SafetyEvent], None] | None = None):
        self.config = config or SafetyConfig()
        self.on_event = on_event
        self.events: list[SafetyEvent] = []
        self.trip_event: SafetyEvent | None = None
        self.clamps = ClampCounts()
        c = self.config
        margin = c.position_margin_rad
        self._q_lo, self._q_hi = _inside_float32(g1.Q_MIN_RAD + margin, g1.Q_MAX_RAD - margin)
        self._dq_lo, self._dq_hi = _inside_float32(-g1.VELOCITY_LIMIT_RADPS, g1.VELOCITY_LIMIT_RADPS)
        self._tau_lo, self._tau_hi = _inside_float32(-g1.EFFORT_LIMIT_NM, g1.EFFORT_LIMIT_NM)
        # Bounds of all clamped fields stacked in CLAMPED_FIELDS order: one clamp for the whole command.
        n = g1.NUM_JOINTS
        lo = {"q_rad": self._q_lo, "dq_radps": self._dq_lo, "tau_nm": self._tau_lo, "kp": 0.0, "kd": 0.0}
        hi = {"q_rad": self._q_hi, "dq_radps": self._dq_hi, "tau_nm": self._tau_hi, "kp": c.max_kp, "kd": c.max_kd}
        self._lo = np.stack([np.broadcast_to(np.asarray(lo[name], dtype=float), n) for name in CLAMPED_FIELDS])
        self._hi = np.stack([np.broadcast_to(np.asarray(hi[name], dtype=float), n) for name in CLAMPED_FIELDS])
        self._raw = np.zeros((len(CLAMPED_FIELDS), n))
        self._changed = np.zeros((len(CLAMPED_FIELDS), n), dtype=bool)
        self._speed_ratio = np.zeros(n)
        self._damping = MotorCommand.damping(c.damping_kd)
        self._crc_burst = _Burst(c.crc_burst_count, c.crc_burst_window_s)
        self._overruns = _Burst(c.overrun_burst_count, c.overrun_window_s)
        self._crc_total_seen: int | None = None
        self.expected_mode_machine: int | None = None
        """The robot's mode_machine as accepted at the start; None: the first state's."""
        self._range_lo = g1.Q_MIN_RAD - c.state_limit_margin_rad
        self._range_hi = g1.Q_MAX_RAD + c.state_limit_margin_rad
        self._tick: int | None = None
        self._tick_since_s = 0.0
        self._last_input_s: float | None = None
        self._last_input: Command = Command()
        self._input_stale = False
        self._ik_failures = 0
        """IK failures in a row (tracker ticks without a new reference)."""
        self.ik_held_ticks = 0
        """Tracker ticks that ran on a held reference because the IK found no solution (all of the run)."""

    @property
    def tripped(self) -> bool:
        return self.trip_event is not None

    # -- inputs that can trip ----------------------------------------------------------------------
    def check(self, state: RobotState, now_s: float) -> bool:
        """Vet `state` (and the input watchdog) at `now_s`; False once tripped."""
        if self.tripped:
            return False
        c = self.config
        # One finite test over everything first (this runs every tick); name the culprit only on failure.
        # (np.add.reduce: ndarray.sum without its Python wrapper; the small vectors as Python floats.)
        add = np.add.reduce
        quat = state.imu_quat_wxyz.tolist()
        total = (add(state.q_rad) + add(state.dq_radps) + add(state.tau_nm) + sum(quat)
                 + sum(state.imu_gyro_radps.tolist()) + sum(state.imu_acc_mps2.tolist()) + add(state.motor_temperature_c))
        if not math.isfinite(total):
            for name in STATE_FIELDS:
                arr = np.asarray(getattr(state, name), dtype=float)
                bad = np.nonzero(~np.isfinite(arr))[0]
                if bad.size:
                    where = g1.JOINT_NAMES[bad[0]] if arr.shape == (g1.NUM_JOINTS,) else f"[{bad[0]}]"
                    return self._trip(now_s, SafetyEventKind.NONFINITE_STATE,
                                      f"RobotState.{name} contains NaN or inf ({where} = {arr[bad[0]]})")
        if not math.isfinite(state.t_s) or not math.isfinite(now_s):
            return self._trip(now_s, SafetyEventKind.NONFINITE_STATE, f"time is not finite (state {state.t_s}, now {now_s})")
        if self.expected_mode_machine is None:
            self.expected_mode_machine = int(state.mode_machine)
        elif state.mode_machine != self.expected_mode_machine:
            return self._trip(now_s, SafetyEventKind.MODE_MACHINE_CHANGED,
                              f"RobotState.mode_machine changed from {self.expected_mode_machine} to "
                              f"{state.mode_machine} (another DoF variant, or a second publisher)")
        outside = (state.q_rad < self._range_lo) | (state.q_rad > self._range_hi)
        if outside.any():
            j = int(np.argmax(outside))
            return self._trip(now_s, SafetyEventKind.STATE_OUT_OF_RANGE,
                              f"RobotState.q_rad ({g1.JOINT_NAMES[j]}) reads {state.q_rad[j]:+.3f} rad, more than "
                              f"{c.state_limit_margin_rad:.2f} rad outside [{g1.Q_MIN_RAD[j]:+.3f}, {g1.Q_MAX_RAD[j]:+.3f}]")
        quat = state.imu_quat_wxyz
        norm = float(np.sqrt(quat @ quat))
        if abs(norm - 1.0) > c.max_quat_norm_error:
            return self._trip(now_s, SafetyEventKind.STATE_OUT_OF_RANGE,
                              f"RobotState.imu_quat_wxyz has norm {norm:.3f} (expected 1 ± {c.max_quat_norm_error:g})")
        if self._tick is not None and state.tick != self._tick:
            step = (int(state.tick) - int(self._tick)) % TICK_MODULUS
            if step >= TICK_MODULUS // 2:
                return self._trip(now_s, SafetyEventKind.STATE_OUT_OF_RANGE,
                                  f"RobotState.tick went back from {self._tick} to {state.tick} (a second publisher, "
                                  "or the robot restarted)")
        age = now_s - state.t_s
        if age > c.stale_state_s:
            return self._trip(now_s, SafetyEventKind.STALE_STATE,
                              f"newest state is {age * 1000:.1f} ms old (limit {c.stale_state_s * 1000:.0f} ms)")
        # A robot whose samples keep arriving with the same tick is as stale as a silent one.
        if state.tick != self._tick:
            self._tick, self._tick_since_s = state.tick, now_s
        elif now_s - self._tick_since_s > c.stale_state_s:
            return self._trip(now_s, SafetyEventKind.STALE_STATE,
                              f"state tick frozen at {state.tick} for {(now_s - self._tick_since_s) * 1000:.1f} ms "
                              f"(limit {c.stale_state_s * 1000:.0f} ms)")
        tilt = tilt_rad(state.imu_quat_wxyz)
        if tilt > c.max_tilt_rad:
            return self._trip(now_s, SafetyEventKind.TILT, f"pelvis tilted {tilt:.2f} rad (limit {c.max_tilt_rad:.2f})")
        speed_ratio = np.divide(np.abs(state.dq_radps, out=self._speed_ratio), g1.VELOCITY_LIMIT_RADPS,
                                out=self._speed_ratio)
        if speed_ratio.max() > c.overspeed_factor:
            j = int(np.argmax(speed_ratio))
            return self._trip(now_s, SafetyEventKind.JOINT_OVERSPEED,
                              f"{g1.JOINT_NAMES[j]} moves at {state.dq_radps[j]:.1f} rad/s "
                              f"(limit {c.overspeed_factor * g1.VELOCITY_LIMIT_RADPS[j]:.1f})")
        if state.motor_temperature_c.max() > c.max_motor_temperature_c:
            j = int(np.argmax(state.motor_temperature_c))
            return self._trip(now_s, SafetyEventKind.OVER_TEMPERATURE,
                              f"{g1.JOINT_NAMES[j]} motor at {state.motor_temperature_c[j]:.0f} °C "
                              f"(limit {c.max_motor_temperature_c:.0f})")
        if self._last_input_s is not None and now_s - self._last_input_s > c.input_lost_s:
            return self._trip(now_s, SafetyEventKind.INPUT_LOST,
                              f"no operator input for {now_s - self._last_input_s:.2f} s (limit {c.input_lost_s:.2f})")
        return True

    def report_crc_errors(self, bad_crc_total: int, now_s: float) -> bool:
        """Feed the transport's running count of bad-CRC states; False once tripped."""
        previous = self._crc_total_seen if self._crc_total_seen is not None else 0
        self._crc_total_seen = bad_crc_total
        new = bad_crc_total - previous
        if new > 0 and self._crc_burst.add(now_s, new) and not self.tripped:
            self._trip(now_s, SafetyEventKind.CRC_BURST,
                       f"{self.config.crc_burst_count} bad-CRC states within {self.config.crc_burst_window_s * 1000:.0f} ms "
                       f"({bad_crc_total} in total)")
        return not self.tripped

    def report_peers(self, fault: str | None, now_s: float) -> bool:
        """Feed the link's complaint about its peers (Backend.peer_fault); False once tripped."""
        if fault and not self.tripped:
            self._trip(now_s, SafetyEventKind.FOREIGN_PEER, fault)
        return not self.tripped

    def expect_mode_machine(self, mode_machine: int) -> None:
        """The mode_machine the preflight accepted: any other one trips."""
        self.expected_mode_machine = int(mode_machine)

    def report_deadline(self, overran: bool, now_s: float, detail: str = "") -> bool:
        """Tell the filter whether this tick missed its deadline; False once tripped."""
        if overran and self._overruns.add(now_s) and not self.tripped:
            self._trip(now_s, SafetyEventKind.DEADLINE_OVERRUNS,
                       f"{self.config.overrun_burst_count} deadline overruns within {self.config.overrun_window_s:.1f} s"
                       + (f" ({detail})" if detail else ""))
        return not self.tripped

    def report_ik_solved(self) -> None:
        """The IK found this tick's reference: a run of failures is over."""
        self._ik_failures = 0

    def report_ik_failure(self, reason: str, now_s: float, can_hold: bool) -> bool:
        """The IK found no solution this tick (reason: its error). While fewer than ik_hold_ticks
        failures came in a row and a good reference exists (can_hold), the tracker keeps the last good
        reference: True (the first failure of a run is logged, not a trip). Otherwise trip: False."""
        if self.tripped:
            return False
        self._ik_failures += 1
        hold = int(self.config.ik_hold_ticks)
        if not can_hold:
            return self._trip(now_s, SafetyEventKind.IK_FAILURE,
                              f"the IK found no solution before any good reference to hold: {reason}")
        if self._ik_failures > hold:
            return self._trip(now_s, SafetyEventKind.IK_FAILURE,
                              f"the IK found no solution on {self._ik_failures} tracker ticks in a row "
                              f"(safety.ik_hold_ticks {hold}): {reason}")
        self.ik_held_ticks += 1
        if self._ik_failures == 1:
            self._log(SafetyEvent(now_s, SafetyEventKind.IK_HOLD,
                                  f"the IK found no solution: the last good reference is held (up to {hold} "
                                  f"tracker ticks): {reason}", trips=False))
        return True

    def estop(self, reason: str, now_s: float, planned: bool = False) -> None:
        """Trip at once (e-stop button, SIGINT/SIGTERM, a fault found elsewhere). planned: an ending the
        operator or the program chose (stop, end of the control time, a signal), logged at INFO."""
        self._trip(now_s, SafetyEventKind.ESTOP, reason, planned)

    def report_fall(self, detail: str, now_s: float) -> None:
        """The robot fell (judged by safety/fall.py): trip, unless already tripped."""
        self._trip(now_s, SafetyEventKind.FALL, detail)

    def vet_input(self, command: Command | None, now_s: float) -> Command:
        """The operator command to act on: `command` when fresh (None = nothing new from the device);
        the last one with zero velocity once input is late; an e-stop button trips."""
        c = self.config
        if command is not None:
            if Button.ESTOP in command.buttons:
                self.estop("e-stop pressed on the operator input", now_s)
            self._last_input_s, self._last_input = now_s, command
            if self._input_stale:
                self._input_stale = False
            return command
        if self._last_input_s is None:
            return Command()
        late = now_s - self._last_input_s
        if late > c.input_zero_velocity_s:
            if not self._input_stale:
                self._input_stale = True
                self._log(SafetyEvent(now_s, SafetyEventKind.INPUT_STALE,
                                      f"no operator input for {late:.2f} s: velocity commands zeroed", trips=False))
            return replace(self._last_input, vx_mps=0.0, vy_mps=0.0, wz_radps=0.0, buttons=frozenset())
        return replace(self._last_input, buttons=frozenset())

    # -- the filter ----------------------------------------------------------------------------------
    def filter(self, command: MotorCommand, state: RobotState, now_s: float) -> MotorCommand:
        """The command to send: clamped, or damping once tripped."""
        if not self.check(state, now_s):
            return self._damping.copy()
        raw = self._raw  # the fields in CLAMPED_FIELDS order
        raw[0], raw[1], raw[2], raw[3], raw[4] = (command.q_rad, command.dq_radps, command.tau_nm, command.kp,
                                                  command.kd)
        # One finite test over all fields (MotorCommand.is_finite's test, on the stacked copy).
        if not math.isfinite(np.add.reduce(raw, axis=None)):
            bad = [n for n in CLAMPED_FIELDS if not np.all(np.isfinite(getattr(command, n)))] or ["values"]
            self._trip(now_s, SafetyEventKind.NONFINITE_COMMAND, f"MotorCommand.{', '.join(bad)} {'contains' if len(bad) == 1 else 'contain'} NaN or inf")
            return self._damping.copy()
        # minimum/maximum rather than np.clip: the same result at a third of the cost per call. The
        # result is new each call (the command handed on owns its arrays: rows of `clamped`).
        clamped = np.minimum(np.maximum(raw, self._lo), self._hi)
        changed = np.not_equal(clamped, raw, out=self._changed)
        if changed.any():
            self.clamps.by_field += changed
            self.clamps.commands += 1
        return MotorCommand(q_rad=clamped[0], dq_radps=clamped[1], tau_nm=clamped[2], kp=clamped[3], kd=clamped[4],
                            enable=np.array(command.enable, dtype=bool))

    def damping(self) -> MotorCommand:
        return self._damping.copy()

    def _trip(self, now_s: float, kind: SafetyEventKind, detail: str, planned: bool = False) -> bool:
        if self.tripped:
            return False
        event = SafetyEvent(float(now_s), kind, detail, trips=True, planned=planned)
        self.trip_event = event
        self._log(event)
        return False

    def _log(self, event: SafetyEvent) -> None:
        self.events.append(event)
        (log.info if event.planned else log.error if event.trips else log.warning)("%s", event)
        if self.on_event is not None:
            self.on_event(event)
