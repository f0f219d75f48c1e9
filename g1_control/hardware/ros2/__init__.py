"""ROS 2 messages over the project's Cyclone DDS, with no ROS installed.

ROS 2's DDS middleware names a topic `rt/<name>` and a message type `<pkg>::msg::dds_::<Name>_`;
a Cyclone DDS participant that uses those names and the same member layout is a ROS 2 node as far
as `ros2 topic echo` and rviz2 on the same domain can tell. `messages.py`
declares the types this project speaks (Twist in; JointState, Odometry, TFMessage out; PoseStamped
in and out: topics.py, the external pose input and g1 sim-robot's motion capture).
"""
