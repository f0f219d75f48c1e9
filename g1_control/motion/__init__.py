"""The G1 motion library: MotionClip (clip.py, fields and units documented there), its edits
(resample.py, mirror.py, edit.py: slice/concat; interpolation.py), forward kinematics
(kinematics.py) and contact labels (contacts.py), handled objects and scene shapes (objects.py),
a built library on disk (library.py), the human-motion input type (human.py, skeletons.py) and
file formats (formats/: Unitree G1 CSV, BeyondMimic/mjlab npz with names, world joint positions
.npy/.pt, BVH). The clip quality metrics are retarget/metrics.py."""
