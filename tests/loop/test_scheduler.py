import pytest

from g1_control.loop.scheduler import Scheduler, Stage


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


def test_wallclock_counts_deadline_misses_and_sleeps_otherwise():
    clock = FakeClock()
    work = {"dt": 0.0005}

    def stage():
        clock.t += work["dt"]

    sched = Scheduler(500, [Stage("work", 500, stage)], wallclock=True, clock=clock, sleep=clock.sleep)
    sched.run(10)
    assert sched.deadline_misses == 0
    assert clock.t == pytest.approx(10 * 0.002)  # slept to each deadline
    work["dt"] = 0.005  # 2.5 ticks of work per tick
    sched.run(4)
    assert sched.deadline_misses == 4 and sched.overruns == 4


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
