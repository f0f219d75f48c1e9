"""Base state estimation (IMU + leg kinematics): velocity (estimator.py), a world pose anchored at the
run start (pose.py, LegOdometry; `g1 bench odometry` measures its drift), an external pose from motion
capture or SLAM fused with it (external_pose.py, PoseFusion), and the estimate in the launch file's
scene frame that goals and programs steer by on the robot (localiser.py, Localiser)."""
