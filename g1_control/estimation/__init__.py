"""Base state estimation (IMU + leg kinematics): velocity (estimator.py) and a world pose anchored
at the run start (pose.py, LegOdometry; `g1 bench odometry` measures its drift)."""
