"""Drive the simulated G1 with commands set from code instead of a launch file's timeline.

    python examples/commands_from_code.py
"""

import numpy as np

import g1_control as g1c

launch = g1c.load_launch("sim_walk", overrides=["duration_s=9"])
commands = g1c.CommandInput()
loop = g1c.build_loop(launch, input_device=commands)
loop.reset()

plan = [(2.0, dict()), (4.0, dict(vx_mps=0.4)), (3.0, dict(wz_radps=0.5))]  # (seconds, command)
for seconds, command in plan:
    commands.set(**command)
    start = loop.time_s
    loop.run(seconds)
    log = loop.log.arrays()
    steady = log["t_s"] > start + min(2.0, seconds / 2)  # skip the acceleration
    achieved = np.mean(log["velocity_true"][steady], axis=0)
    print(f"{start:4.1f}-{loop.time_s:4.1f} s  command {command or 'stand'}: achieved vx {achieved[0]:+.2f} m/s, "
          f"wz {achieved[2]:+.2f} rad/s")
loop.backend.close()
assert not loop.fell, "the robot fell"
