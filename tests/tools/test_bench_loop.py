"""`g1 bench loop`'s baseline is the loop's own physics: a second backend started from a copy of the
loop's MjData and handed the commands the loop wrote (CommandRecorder) ends in exactly the loop's state,
while the loop, walking, ends somewhere a replay of other commands would not."""

from __future__ import annotations

import mujoco
import numpy as np

from g1_control.launch.builder import build_loop, make_sim_backend
from g1_control.tools.bench_loop import CommandRecorder, bench_launch


def test_replaying_the_recorded_commands_reproduces_the_loops_physics_exactly():
    launch = bench_launch(4.0)
    sim = make_sim_backend(launch)
    loop = build_loop(launch, backend=sim)
    loop.reset()
    loop.scheduler.run(500)  # 1 s standing
    recorder = CommandRecorder(sim)
    replay = make_sim_backend(launch)
    replay.reset()
    mujoco.mj_copyData(replay.data, replay.model, sim.data)
    start = mujoco.MjData(replay.model)
    mujoco.mj_copyData(start, replay.model, sim.data)
    start_qpos = sim.data.qpos.copy()
    loop.scheduler.run(1000)  # 2 s: standing, then walking forward
    calls = recorder.take()
    assert sum(n for _, _, n in calls) == 1000 and recorder.take() == []
    assert len({id(c) for c, _, _ in calls}) >= 50, "the tracker's commands (50 Hz), not one command"
    for command, dt_s, n in calls:
        replay.step_ticks(command, dt_s, n)
    assert np.array_equal(replay.data.qpos, sim.data.qpos) and np.array_equal(replay.data.qvel, sim.data.qvel)
    assert float(replay.data.time) == float(sim.data.time)
    assert np.abs(sim.data.qpos[:3] - start_qpos[:3]).max() > 0.05, "the robot moved: the replay is not trivial"

    # The comparison can tell: the same ticks from the same start with only the first command held
    # end elsewhere.
    held = make_sim_backend(launch)
    held.reset()
    mujoco.mj_copyData(held.data, held.model, start)
    for _, dt_s, n in calls:
        held.step_ticks(calls[0][0], dt_s, n)
    assert np.abs(held.data.qpos - sim.data.qpos).max() > 1e-3
    loop.input.close()
