"""Real-robot transports (installed as g1_control.hardware).

Messages and codecs: unitree_hg (LowCmd_/LowState_, C and DDS byte forms), layout, crc,
conversions (to/from RobotState and MotorCommand). Links, one per transport: dds_link (Cyclone DDS
0.10.x), serial_link (pyserial), can_link (python-can), over framing/stream_link for byte links.
link_backend.LinkBackend is the host-side Backend over any link; dds_backend.UnitreeDDSBackend
adds the motion-service release. The robot side: robot_endpoint, mock_robot, emulator
(`g1 sim-robot`), fault_suite. DDS pieces import cyclonedds lazily: the rest works without it.
"""
