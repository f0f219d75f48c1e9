"""Real-robot transports (installed as g1_control.hardware).

    unitree/          the G1 low-level protocol, written from its facts: unitree/messages.py
                      (LowCmd_/LowState_, C and DDS byte forms), unitree/layout.py, unitree/crc.py,
                      unitree/idl.py, unitree/conversions.py (to/from RobotState and MotorCommand),
                      unitree/motion_service.py, unitree/remote.py (the handheld remote's bytes);
                      the Dex3-1 hands' HandCmd_/HandState_: unitree/hand_idl.py, unitree/hand_messages.py
    links/            one link per transport: links/dds.py (Cyclone DDS 0.10.x), links/serial_port.py
                      (pyserial), links/can_bus.py (python-can), over links/framing.py and
                      links/stream.py for byte links; links/base.py (Link), links/network.py
    link_backend.py   LinkBackend: the host-side Backend over any link
    dds_backend.py    UnitreeDDSBackend: LinkBackend over DDS, with the motion-service release
    hand_link.py      Dex3HandLink: the host side of both Dex3-1 hands over DDS (rt/dex3/left|right/...)

The robot side is in sim/ (sim/robot_endpoint.py, sim/mock_robot.py, sim/emulator.py for
`g1 sim-robot`), the fault suite in tools/fault_suite.py. DDS pieces import cyclonedds lazily:
the rest works without it.
"""
