"""The generator's G1 motion library: `g1 library build` collects MotionClips from physics
rollouts of the locomotion tracker (per upper-body style), the WBT dance clip, retargeted human
demos and their left/right mirrors, cuts them into clips and writes an index with style labels
and a held-out split by clip.

    builder.py    sources -> clips cut into pieces -> mirrored -> split by clip -> written, cached
    rollouts.py   physics rollouts of the locomotion tracker, one upper-body style per rollout
    dance.py      the WBT policy's dance clip
    variants.py   the libraries of the other G1 variants, derived from the 29-DoF one

The library on disk (clips and index.json) is read and written by motion/library.py.
"""
