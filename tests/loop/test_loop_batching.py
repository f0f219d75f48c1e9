"""In lockstep the loop runs the low-level-only ticks between tracker ticks as one backend call
(loop/scheduler.py, Backend.step_ticks); the run is the same as tick by tick."""

import numpy as np

from g1_control.interfaces import Backend
from g1_control.launch.builder import build_loop
from g1_control.launch.schema import LaunchFile, Segment
from g1_control.sim.mujoco_backend import MujocoBackend


class TickByTick(MujocoBackend):
    """The backend as the interface's default drives it: one write_command and one step per tick."""

    step_ticks = Backend.step_ticks

    def __init__(self):
        self.writes = self.steps = 0
        super().__init__()

    def write_command(self, command):
        self.writes += 1
        super().write_command(command)

    def step(self, dt_s):
        self.steps += 1
        super().step(dt_s)


def _run(backend):
    launch = LaunchFile(name="batching")
    launch.input.timeline = [Segment(0.2, label="stand"), Segment(0.8, vx_mps=0.4, label="walk")]
    launch.output.video = "off"
    loop = build_loop(launch, backend=backend)
    loop.reset()
    loop.run(1.0)
    return loop


def test_batched_low_level_ticks_give_the_same_run_as_single_ticks():
    batched, single = _run(MujocoBackend()), _run(TickByTick())
    assert single.backend.steps == 500 and single.backend.writes >= 500  # every tick wrote and stepped
    assert batched.scheduler.tick_index == single.scheduler.tick_index == 500
    a, b = batched.log.arrays(), single.log.arrays()
    for name in a:
        np.testing.assert_array_equal(a[name], b[name], err_msg=name)
    np.testing.assert_array_equal(batched.backend.data.qpos, single.backend.data.qpos)
    assert batched.scheduler.report()["lowlevel"]["calls"] == 500
