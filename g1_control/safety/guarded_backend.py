"""GuardedBackend: any Backend behind a SafetyFilter, so nothing reaches the motors unvetted.

    robot = GuardedBackend(UnitreeDDSBackend("lo", 1))
    install_signal_damping(robot)           # SIGINT/SIGTERM -> damping on the wire at once
    robot.reset()
    robot.write_command(cmd)                # clamped, or damping once anything tripped

Wall-clock backends are judged on time.monotonic() (the clock their states are stamped with);
lockstep backends on the state's own simulation time, where staleness cannot happen.
The transport's bad-CRC count (LinkBackend.bad_crc) feeds the CRC-burst watchdog on every write,
and its peer check (LinkBackend.peer_fault: a second publisher of the robot's state) trips it.
"""

from __future__ import annotations

import signal
import time
from collections.abc import Callable

from g1_control.interfaces import Backend
from g1_control.safety.config import SafetyConfig
from g1_control.safety.events import SafetyEvent
from g1_control.safety.filter import SafetyFilter
from g1_control.types import MotorCommand, RobotState


class GuardedBackend(Backend):
    def __init__(self, inner: Backend, config: SafetyConfig | None = None,
                 on_event: Callable[[SafetyEvent], None] | None = None,
                 clock: Callable[[], float] | None = None):
        self.inner = inner
        self.lockstep = inner.lockstep
        self.safety = SafetyFilter(config, on_event=on_event)
        self._clock = clock or (None if inner.lockstep else time.monotonic)
        self.last_sent: MotorCommand | None = None

    def now_s(self, state: RobotState) -> float:
        return self._clock() if self._clock is not None else state.t_s

    def reset(self) -> RobotState:
        return self.inner.reset()

    def read_state(self) -> RobotState:
        return self.inner.read_state()

    def write_command(self, command: MotorCommand) -> None:
        state = self.inner.read_state()
        now = self.now_s(state)
        self.safety.report_crc_errors(self.inner.bad_crc, now)
        self.safety.report_peers(self.inner.peer_fault, now)
        out = self.safety.filter(command, state, now)
        self.last_sent = out
        self.inner.write_command(out)

    def report_deadline(self, overran: bool, detail: str = "") -> None:
        now = self._clock() if self._clock is not None else self.inner.read_state().t_s
        if not self.safety.report_deadline(overran, now, detail):
            self._damp_now()

    def estop(self, reason: str, planned: bool = False) -> None:
        """Trip and put damping on the wire now, without waiting for the next tick."""
        now = self._clock() if self._clock is not None else float("nan")
        self.safety.estop(reason, now, planned)
        self._damp_now()

    def _damp_now(self) -> None:
        # The link's own damping first (on the wire at once), then the filter's, with its kd.
        self.inner.damp()
        self.inner.write_command(self.safety.damping())

    def step(self, dt_s: float) -> None:
        self.inner.step(dt_s)

    def close(self) -> None:
        self.inner.close()


def install_signal_damping(robot: GuardedBackend, signals=(signal.SIGINT, signal.SIGTERM)) -> None:
    """On each of `signals`: e-stop the robot (damping streamed at once), then raise KeyboardInterrupt
    in the main thread so the program unwinds through its `with`/finally blocks, which close()."""

    def handler(signum, frame):
        robot.estop(f"{signal.Signals(signum).name} received", planned=True)
        raise KeyboardInterrupt

    for sig in signals:
        signal.signal(sig, handler)
