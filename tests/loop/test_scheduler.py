import numpy as np
import pytest

from g1_control.loop.scheduler import Scheduler, Stage, StageTimes


class FakeClock:
    def __init__(self):
        self.t = 0.0

    def __call__(self):
        return self.t

    def sleep(self, s):
        self.t += s


def test_stages_run_at_their_rates_in_order():
    calls = []
    stages = [Stage("input", 100, lambda: calls.append("input")), Stage("tracker", 50, lambda: calls.append("tracker")),
              Stage("lowlevel", 500, lambda: calls.append("lowlevel"))]
    sched = Scheduler(500, stages)
    sched.run(500)
    assert calls.count("lowlevel") == 500 and calls.count("input") == 100 and calls.count("tracker") == 50
    assert calls[:3] == ["input", "tracker", "lowlevel"]
    assert sched.time_s == pytest.approx(1.0)
    report = sched.report()
    assert report["tracker"]["calls"] == 50 and report["tick"]["calls"] == 500


def test_rate_that_does_not_divide_base_is_refused():
    with pytest.raises(ValueError, match="stage 'tracker' rate 30 Hz does not divide the base rate 500"):
        Scheduler(500, [Stage("tracker", 30, lambda: None)])


def _working(dt: float) -> tuple[FakeClock, dict, Scheduler]:
    """A 500 Hz wall-clock scheduler on a fake clock whose one stage takes work["dt"] of it per tick."""
    clock = FakeClock()
    work = {"dt": dt}

    def stage():
        clock.t += work["dt"]

    return clock, work, Scheduler(500, [Stage("work", 500, stage)], wallclock=True, clock=clock, sleep=clock.sleep)


def test_wallclock_counts_deadline_misses_and_sleeps_otherwise():
    clock, work, sched = _working(0.0005)
    sched.run(10)
    assert sched.deadline_misses == 0
    assert clock.t == pytest.approx(10 * 0.002)  # slept to each deadline
    work["dt"] = 0.0051  # 2.5 ticks of work per tick: every tick that runs misses, the periods lost are skipped
    sched.run(8)
    assert sched.deadline_misses == sched.overruns == 4
    assert sched.skipped_ticks == 6 and sched.tick_index == 20  # 4 ran + 6 skipped >= 8 ticks of control time
    assert sched.time_s == pytest.approx(clock.t, abs=0.002)  # control time stayed the wall clock's


def test_a_stall_is_one_miss_and_the_ticks_after_it_are_on_time():
    """One tick stalls for 5 periods (a preempted thread); the ticks after it run on the wall clock's
    schedule again at once, not back to back to catch up (each of those would finish late too)."""
    clock = FakeClock()
    stalls = {4: 0.0105}
    ran: list[int] = []

    def stage():
        ran.append(sched.tick_index)
        clock.t += stalls.get(sched.tick_index, 0.0012)  # 60 % of the 2 ms period, 10.5 ms once

    sched = Scheduler(500, [Stage("work", 500, stage)], wallclock=True, clock=clock, sleep=clock.sleep)
    assert sched.run(20) == 20
    assert sched.deadline_misses == 1 and sched.misses_over_period == 1
    assert sched.max_lateness_s == pytest.approx(0.0105 - 0.002)
    assert sched.skipped_ticks == 4 and ran == [*range(5), *range(9, 20)]  # ticks 5-8 lost to the stall
    assert clock.t == pytest.approx(20 * 0.002)  # ends on the 20th deadline, as without the stall
    late = sched.lateness.samples[:sched.lateness.count]
    assert (late > 0).sum() == 1


def test_a_tick_late_by_less_than_a_period_is_a_miss_and_its_lateness_reaches_the_safety_layer():
    """A tick that finishes 0.5 ms past its deadline (less than the 2 ms period) counts as a miss, and
    take_lateness (what the loop hands the safety layer's overrun check) reports it once."""
    _, work, sched = _working(0.001)
    sched.run(3)
    assert sched.take_lateness() == 0.0 and sched.deadline_misses == 0
    work["dt"] = 0.0025
    sched.run(1)
    assert sched.deadline_misses == 1 and sched.misses_over_period == 0 and sched.skipped_ticks == 0
    assert sched.take_lateness() == pytest.approx(0.0005)
    assert sched.take_lateness() == 0.0  # taken: the next call reports only what came after


def test_lockstep_never_sleeps_but_counts_overruns():
    clock = FakeClock()

    def slow():
        clock.t += 0.003

    sched = Scheduler(500, [Stage("slow", 500, slow)], clock=clock, sleep=lambda s: pytest.fail("slept"))
    sched.run(3)
    assert sched.overruns == 3 and sched.deadline_misses == 0


def test_timing_percentiles():
    clock = FakeClock()
    durations = iter([0.001] * 99 + [0.010])

    def stage():
        clock.t += next(durations)

    sched = Scheduler(100, [Stage("s", 100, stage)], clock=clock)
    sched.run(100)
    r = sched.report()["s"]
    assert r["p50_us"] == pytest.approx(1000.0)
    assert 1000.0 < r["p99_us"] <= 10000.0 and r["max_us"] == pytest.approx(10000.0)


def _recording_stages(calls, batch_every_tick=True):
    def every_tick():
        calls.append("low")

    def batch(n):
        calls.extend(["low"] * n)
        calls.append(f"batch{n}")

    return [Stage("tracker", 50, lambda: calls.append("tracker")), Stage("input", 100, lambda: calls.append("input")),
            Stage("low", 500, every_tick, batch=batch if batch_every_tick else None)]


def test_lockstep_runs_low_level_only_ticks_as_one_batch():
    calls = []
    sched = Scheduler(500, _recording_stages(calls))
    seen = []
    assert sched.run(20, progress=seen.append) == 20
    plain = [c for c in calls if not c.startswith("batch")]
    # The same calls in the same order as tick by tick: every tick's stages, then the next tick's.
    expected = (["tracker", "input", "low"] + ["low"] * 4 + ["input", "low"] + ["low"] * 4) * 2
    assert plain == expected
    assert [c for c in calls if c.startswith("batch")] == ["batch4"] * 4
    assert seen == list(range(20))  # progress still hears of every tick
    assert sched.tick_index == 20 and sched.time_s == pytest.approx(0.04)
    report = sched.report()
    assert report["low"]["calls"] == 20 and report["tick"]["calls"] == 20 and report["tracker"]["calls"] == 2


def test_stop_is_asked_before_every_batch_and_every_tick():
    calls = []
    sched = Scheduler(500, _recording_stages(calls))
    asked = []

    def stop():
        asked.append(sched.tick_index)
        return sched.tick_index >= 5

    assert sched.run(20, stop=stop) == 5
    assert asked == [0, 1, 5]


def test_no_batch_on_the_wall_clock_or_without_a_batch_function():
    for kwargs, batch in (({"wallclock": True, "clock": FakeClock(), "sleep": lambda s: None}, True), ({}, False)):
        calls = []
        Scheduler(500, _recording_stages(calls, batch_every_tick=batch), **kwargs).run(10)
        assert not [c for c in calls if c.startswith("batch")]
        assert calls.count("low") == 10


def test_two_stages_due_every_tick_are_never_batched():
    calls = []
    stages = [Stage("a", 500, lambda: calls.append("a"), batch=lambda n: calls.append("batch")),
              Stage("b", 500, lambda: calls.append("b"), batch=lambda n: calls.append("batch"))]
    Scheduler(500, stages).run(3)
    assert calls == ["a", "b"] * 3


def test_batched_ticks_are_timed_per_tick():
    clock = FakeClock()

    def batch(n):
        clock.t += 0.001 * n  # 1 ms per tick of work

    sched = Scheduler(500, [Stage("slow", 50, lambda: None), Stage("low", 500, lambda: None, batch=batch)], clock=clock)
    sched.run(10)
    low = sched.times["low"]
    assert low.count == 10
    np.testing.assert_allclose(low.samples[1:10], 0.001)
    assert sched.overruns == 0


def test_time_ring_buffer_wraps_for_batches():
    times = StageTimes(capacity=8)
    times.add_repeated(1.0, 6)
    times.add_repeated(2.0, 5)
    assert times.count == 11
    np.testing.assert_array_equal(times.samples, [2.0, 2.0, 2.0, 1.0, 1.0, 1.0, 2.0, 2.0])


def test_batch_lengths_follow_every_stage_s_period():
    calls = []
    stages = [Stage("a", 100, lambda: calls.append("a")), Stage("b", 125, lambda: calls.append("b")),
              Stage("low", 500, lambda: calls.append("low"), batch=lambda n: calls.append(n))]
    Scheduler(500, stages).run(40)  # a every 5 ticks, b every 4: batches between their ticks
    due = [k for k in range(40) if k % 5 == 0 or k % 4 == 0]
    expected_batches = [b - a - 1 for a, b in zip(due, due[1:] + [40]) if b - a - 1 > 1]
    assert [c for c in calls if isinstance(c, int)] == expected_batches
    assert calls.count("low") + sum(expected_batches) == 40


def test_batches_without_the_phase_table_are_the_same():
    def run(table):
        calls = []
        stages = [Stage("a", 100, lambda: calls.append("a")), Stage("b", 125, lambda: calls.append("b")),
                  Stage("low", 500, lambda: calls.append("low"), batch=lambda n: calls.append(n))]
        sched = Scheduler(500, stages)
        if not table:
            sched._runs = None  # as for stage periods whose common cycle is too long to tabulate
        sched.run(97)
        return calls

    assert run(True) == run(False)
