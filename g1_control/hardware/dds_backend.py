"""UnitreeDDSBackend: the real G1 (or `g1 sim-robot`) over Cyclone DDS.

    with UnitreeDDSBackend(interface="lo", domain_id=1) as robot:   # emulator on loopback
        state = robot.reset()           # releases the built-in controller, waits for LowState
        robot.write_command(cmd)        # streamed at 500 Hz until the next one

The real robot: domain 0, the NIC on 192.168.123.0/24, robot hanging on a gantry for first runs.
"""

from __future__ import annotations

from g1_control.hardware.link_backend import LinkBackend
from g1_control.hardware.links.dds import DdsLink
from g1_control.hardware.unitree.motion_service import release_motion_service
from g1_control.types import RobotState


class UnitreeDDSBackend(LinkBackend):
    def __init__(self, interface: str, domain_id: int = 0, *, release_motion_service: bool = True,
                 partition: str | None = None, motion_service_timeout_s: float = 5.0, **kwargs):
        """interface: network interface to bind (required; 'lo' for simulation).
        release_motion_service: False for operators who put the robot in debug mode with the remote.
        partition: DDS partition; None (the robot's) except to isolate tests sharing one host.
        Other keywords: see LinkBackend (command_rate_hz, mode_pr, expected_mode_machine, ...)."""
        self.release_motion_service = release_motion_service
        self.motion_service_timeout_s = motion_service_timeout_s
        self.released_modes: list[str] = []
        self._dds = DdsLink("host", interface, domain_id, partition=partition)
        super().__init__(self._dds, **kwargs)

    def reset(self) -> RobotState:
        if self.release_motion_service:
            link = self._dds  # self.link, typed as the DDS link it is
            self.released_modes = release_motion_service(link._participant, link.partition,
                                                         timeout_s=self.motion_service_timeout_s)
        return super().reset()
