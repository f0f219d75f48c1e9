"""Build the control loop a launch file describes and run it from Python.

    python examples/run_launch_file.py [LAUNCH] [SECONDS]

The loop is the same object `g1 launch` and `g1 deploy` run (g1_control/launch/builder.py).
"""

import sys

import numpy as np

import g1_control as g1c

name = sys.argv[1] if len(sys.argv) > 1 else "sim_walk"
seconds = float(sys.argv[2]) if len(sys.argv) > 2 else 6.0

launch = g1c.load_launch(name, overrides=[f"duration_s={seconds}"])
loop = g1c.build_loop(launch)
for stage, what in loop.chain.items():
    print(f"{stage:10s} {what}")
loop.reset()
loop.run(seconds)  # lockstep MuJoCo: as fast as the CPU allows

log = loop.log.arrays()
last = log["t_s"] > seconds - 2.0
vx = float(np.mean(log["velocity_true"][last, 0]))
print(f"simulated {loop.time_s:.1f} s; fell: {loop.fell}; last 2 s: commanded vx "
      f"{log['command'][-1, 0]:+.2f}, achieved vx {vx:+.2f} m/s (ground truth)")
loop.backend.close()
sys.exit(1 if loop.fell else 0)
