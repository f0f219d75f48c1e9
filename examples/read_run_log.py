"""Read a run folder back into numpy and pandas.

    python examples/read_run_log.py [RUN_FOLDER]

Without a folder it first makes a short one (sim_walk, 8 s, no video) under ./runs.
"""

import sys

import g1_control as g1c

if len(sys.argv) > 1:
    folder = sys.argv[1]
else:
    launch = g1c.load_launch("sim_walk", overrides=["duration_s=8", "output.video=false"])
    folder = g1c.run(launch, out="runs").run_dir
record = g1c.read_run(folder)

log = record.log  # numpy: one row per tracker tick
print(f"{record.path}: {len(log['t_s'])} ticks, arrays: {', '.join(log)}")
print(f"pelvis height: mean {log['base_pos_m'][:, 2].mean():.3f} m")
for seg in record.summary.get("segments", []):
    print(f"  {seg['label']:10s} {seg['start_s']:5.1f}-{seg['end_s']:5.1f} s  commanded vx {seg['commanded'][0]:+.2f}, "
          f"achieved {seg['achieved'][0]:+.2f}")

try:
    frame = record.dataframe()  # pandas, indexed by time
except g1c.G1ControlError as exc:
    print(f"(no pandas: {exc})")
else:
    per_second = frame[["command_vx", "velocity_true_vx", "velocity_est_vx"]].groupby(frame.index // 1).mean()
    print(per_second.tail(4).round(3).to_string())
