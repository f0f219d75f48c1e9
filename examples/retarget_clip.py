"""Retarget human motion capture to the G1 with the pinocchio IK, save the clip, look at it.

    python examples/retarget_clip.py [MOCAP_FILE] [OUT.npz]

Without a file it takes the first 1.5 s of a demo sequence (`g1 policies fetch --asset
holosoma-demo-mocap` fetches them; scripts/setup.sh --test does). Then: g1 view OUT.npz
"""

import dataclasses
import sys
from pathlib import Path

import numpy as np

import g1_control as g1c

if len(sys.argv) > 1:
    motion = g1c.load_clip(sys.argv[1])
else:
    from g1_control.assets import fetch

    demo = sorted((fetch("holosoma-demo-mocap") / "holosoma_retargeting" / "demo_data").glob("climb/*/*.npy"))[0]
    motion = g1c.load_clip(demo)
    frames = int(1.5 * motion.fps)
    motion = dataclasses.replace(motion, positions_w_m=motion.positions_w_m[:frames])
    if motion.object is not None:
        motion = dataclasses.replace(motion, object=None)
out = Path(sys.argv[2]) if len(sys.argv) > 2 else Path("retargeted.npz")

print(f"{motion.source}: {motion.positions_w_m.shape[0]} frames of {len(motion.joint_names)} human joints")
clip = g1c.retarget(motion, fps=50.0)
g1c.save_clip(clip, out)
back = g1c.load_clip(out)
lo, hi = np.asarray(g1c.g1.Q_MIN_RAD), np.asarray(g1c.g1.Q_MAX_RAD)
inside = bool(np.all((back.joint_pos_rad >= lo - 1e-6) & (back.joint_pos_rad <= hi + 1e-6)))
print(f"wrote {out}: {back.joint_pos_rad.shape[0]} G1 frames at {back.fps:g} fps, joints inside their limits: {inside}")
print(f"look at it: g1 view {out}")
assert inside
