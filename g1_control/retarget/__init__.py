"""Offline retargeting of human motion capture to the G1 (mocap.py) and the clip quality metrics
(metrics.py). Sits above ik/ and motion/."""
