"""Base state estimation (IMU + leg kinematics)."""
