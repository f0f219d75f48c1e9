"""The generator's G1 motion library: `g1 library build` collects MotionClips from physics
rollouts of the locomotion tracker (per upper-body style), the WBT dance clip, retargeted human
demos and their left/right mirrors, cuts them into clips and writes an index with style labels
and a held-out split by clip (index.py)."""
