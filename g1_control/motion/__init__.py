"""The G1 motion library: MotionClip (clip.py, fields and units documented there), its edits
(resample, mirror, slice/concat), forward kinematics and contact labels, quality metrics, the
human-motion input type (human.py, skeletons.py) and file formats (formats/: Unitree G1 CSV,
BeyondMimic/mjlab npz with names, world joint positions .npy/.pt, BVH)."""
