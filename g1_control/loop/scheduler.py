"""Multi-rate fixed-rate scheduling with per-stage timing and deadline-miss counting.

One base tick runs at the fastest rate (the low-level command stream). Every stage runs on
ticks that are a multiple of its period, in the order the stages were given, so one tick is
"input, estimator, generator, tracker, safety, low-level" when all are due. The same code runs
in lockstep (as fast as possible; the backend advances simulated time) and in wall-clock mode
(each tick waits for its deadline). A tick that ends after its deadline is a deadline miss; one that
ends more than a whole period late skips the periods it lost (tick_index moves on by them, so the
control time stays the wall clock's) instead of running the missed ticks back to back.

In lockstep, ticks on which only the one every-tick stage is due (the low-level stream between
tracker ticks) run as one call of that stage's `batch(n)` when it has one: n ticks of the stage
with nothing in between, so the result is the same (a simulator steps its physics n times at once).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np


@dataclass
class Stage:
    name: str
    rate_hz: float
    fn: Callable[[], None]
    period_ticks: int = 0
    batch: Callable[[int], None] | None = None
    """Optional: run the stage for n consecutive ticks in one call (lockstep only; see the module doc)."""


@dataclass
class StageTimes:
    """Durations of a stage's calls (seconds), in a preallocated ring buffer."""

    capacity: int = 1 << 16
    samples: np.ndarray = field(init=False)
    count: int = 0

    def __post_init__(self) -> None:
        self.samples = np.zeros(self.capacity)

    def add(self, seconds: float) -> None:
        self.samples[self.count % self.capacity] = seconds
        self.count += 1

    def add_repeated(self, seconds: float, n: int) -> None:
        """`n` calls of `seconds` each (a batch of ticks, timed as a whole)."""
        start = self.count % self.capacity
        stop = min(start + n, self.capacity)
        self.samples[start:stop] = seconds
        if start + n > stop:
            self.samples[: min(start + n - stop, self.capacity)] = seconds
        self.count += n

    def summary(self) -> dict[str, float]:
        data = self.samples[: min(self.count, self.capacity)]
        if data.size == 0:
            return {"calls": 0, "p50_us": 0.0, "p99_us": 0.0, "max_us": 0.0, "mean_us": 0.0}
        p50, p99 = np.percentile(data, [50, 99]) * 1e6
        return {"calls": self.count, "p50_us": float(p50), "p99_us": float(p99),
                "max_us": float(data.max() * 1e6), "mean_us": float(data.mean() * 1e6)}


class Scheduler:
    def __init__(self, base_rate_hz: float, stages: list[Stage], *, wallclock: bool = False,
                 clock: Callable[[], float] = time.perf_counter, sleep: Callable[[float], None] = time.sleep):
        if base_rate_hz <= 0:
            raise ValueError(f"base rate must be positive, got {base_rate_hz}")
        self.base_rate_hz = base_rate_hz
        self.dt_s = 1.0 / base_rate_hz
        self.stages = stages
        for stage in stages:
            ratio = base_rate_hz / stage.rate_hz
            if stage.rate_hz <= 0 or abs(ratio - round(ratio)) > 1e-9:
                raise ValueError(f"stage '{stage.name}' rate {stage.rate_hz} Hz does not divide the base rate "
                                 f"{base_rate_hz} Hz into whole ticks")
            stage.period_ticks = round(ratio)
        self.wallclock = wallclock
        self.clock = clock
        self.sleep = sleep
        self.times = {s.name: StageTimes() for s in stages}
        self.tick_times = StageTimes()
        self.tick_index = 0
        self.deadline_misses = 0
        self.overruns = 0
        """Ticks whose compute alone took longer than the tick period (would miss in real time)."""
        self.lateness = StageTimes(capacity=1 << 14)
        """How late each wall-clock tick finished past its deadline (0 when on time), seconds."""
        self.max_lateness_s = 0.0
        self.misses_over_period = 0
        """Ticks that finished more than a whole tick period late (the next tick's deadline passed too)."""
        self.skipped_ticks = 0
        """Wall-clock ticks not run: the whole periods a late tick overran (tick_index moves past them)."""
        self.on_skip: Callable[[int], None] | None = None
        """Called with the number of ticks skipped, when a late tick skips them (a simulator steps them)."""
        self._late_since_take = 0.0
        self._late_since_log = 0.0
        self._t0: float | None = None
        self._timed = [(s.period_ticks, s.fn, self.times[s.name]) for s in stages]
        every_tick = [s for s in stages if s.period_ticks == 1]
        self._batched = every_tick[0] if len(every_tick) == 1 and every_tick[0].batch is not None else None
        self._others = [s.period_ticks for s in stages if s.period_ticks > 1]
        # Per phase of the stages' common cycle: how many ticks from it on only the batched stage is due.
        self._cycle = math.lcm(*self._others) if self._others else 1
        self._runs: list[int] | None = None
        if self._others and self._cycle <= 1 << 16:
            self._runs = [0] * self._cycle
            due_next = self._cycle  # phase 0 of the next cycle: every stage is due
            for k in reversed(range(self._cycle)):
                if any(k % period == 0 for period in self._others):
                    due_next = k
                self._runs[k] = due_next - k

    @property
    def time_s(self) -> float:
        """Control time: ticks run so far times the tick period."""
        return self.tick_index * self.dt_s

    def tick(self) -> None:
        clock = self.clock
        if self._t0 is None:
            self._t0 = clock()
        start = clock()
        k = self.tick_index
        for period, fn, times in self._timed:
            if k % period == 0:
                s0 = clock()
                fn()
                times.add(clock() - s0)
        end = clock()
        self.tick_times.add(end - start)
        if end - start > self.dt_s:
            self.overruns += 1
        self.tick_index += 1
        if self.wallclock:
            deadline = self._t0 + self.tick_index * self.dt_s
            late = end - deadline
            self.lateness.add(max(0.0, late))
            if late > 0:
                self.deadline_misses += 1
                self.max_lateness_s = max(self.max_lateness_s, late)
                if late > self.dt_s:
                    self.misses_over_period += 1
                    # The whole periods lost are skipped, not run back to back to catch up: after a stall
                    # of a few ticks every catch-up tick would finish late too (a controller using most of
                    # its period catches up slowly), each counted as one more overrun, and they would
                    # act on almost the same state. Control time stays the wall clock's.
                    lost = int(late // self.dt_s)
                    self.tick_index += lost
                    self.skipped_ticks += lost
                    if self.on_skip is not None:
                        self.on_skip(lost)
                self._late_since_take = max(self._late_since_take, late)
                self._late_since_log = max(self._late_since_log, late)
            else:
                self.sleep(-late)

    def take_lateness(self) -> float:
        """The worst lateness since the previous call (0 when every tick was on time)."""
        late, self._late_since_take = self._late_since_take, 0.0
        return late

    def take_log_lateness(self) -> float:
        """As take_lateness, for the run log (its own account: the safety layer takes the other)."""
        late, self._late_since_log = self._late_since_log, 0.0
        return late

    def _batchable(self, limit: int) -> int:
        """How many ticks from now (at most `limit`) only the batched stage is due on."""
        if self._batched is None or self.wallclock:
            return 0
        k = self.tick_index
        if self._runs is not None:
            return min(self._runs[k % self._cycle], limit)
        n = limit
        for period in self._others:
            n = min(n, -k % period)
        return n

    def _run_batch(self, n: int) -> None:
        stage = self._batched
        assert stage is not None and stage.batch is not None  # _batchable() said so
        clock = self.clock
        if self._t0 is None:
            self._t0 = clock()
        start = clock()
        stage.batch(n)
        end = clock()
        each = (end - start) / n
        self.times[stage.name].add_repeated(each, n)
        self.tick_times.add_repeated(each, n)
        if each > self.dt_s:
            self.overruns += n
        self.tick_index += n

    def run(self, n_ticks: int, stop: Callable[[], bool] | None = None,
            progress: Callable[[int], None] | None = None) -> int:
        """Run up to `n_ticks` ticks of control time; returns how many passed (fewer when `stop()` turns
        true). Ticks a late wall-clock tick skipped count as passed."""
        start = self.tick_index
        i = 0
        while i < n_ticks:
            if stop is not None and stop():
                return i
            n = self._batchable(n_ticks - i)
            if n > 1:
                self._run_batch(n)
            else:
                self.tick()
            done = min(self.tick_index - start, n_ticks)
            if progress is not None:
                for j in range(i, done):
                    progress(j)
            i = done
        return n_ticks

    def report(self) -> dict[str, dict[str, float]]:
        out = {name: t.summary() for name, t in self.times.items()}
        out["tick"] = self.tick_times.summary()
        return out
