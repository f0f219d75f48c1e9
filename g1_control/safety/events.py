"""SafetyEvent: one line of the safety log."""

from __future__ import annotations

from dataclasses import dataclass
from enum import Enum


class SafetyEventKind(str, Enum):
    STALE_STATE = "stale_state"
    CRC_BURST = "crc_burst"
    TILT = "tilt"
    JOINT_OVERSPEED = "joint_overspeed"
    NONFINITE_STATE = "nonfinite_state"
    NONFINITE_COMMAND = "nonfinite_command"
    DEADLINE_OVERRUNS = "deadline_overruns"
    INPUT_STALE = "input_stale"
    """Not a trip: velocity commands zeroed while the operator input is late."""
    INPUT_LOST = "input_lost"
    OVER_TEMPERATURE = "over_temperature"
    FALL = "fall"
    """The robot fell (g1_control/safety/fall.py: tilt, pelvis low, a body other than the feet on the ground)."""
    STATE_OUT_OF_RANGE = "state_out_of_range"
    """A joint reads far outside its limits, the IMU quaternion is not a unit quaternion, or the tick ran backwards."""
    MODE_MACHINE_CHANGED = "mode_machine_changed"
    """The robot reports another mode_machine (DoF variant) than the one accepted at the start."""
    FOREIGN_PEER = "foreign_peer"
    """A second publisher of the robot's state, or another writer of its commands, on the link."""
    IK_HOLD = "ik_hold"
    """Not a trip: the IK found no solution this tick; the tracker keeps the last good reference
    (for up to SafetyConfig.ik_hold_ticks tracker ticks in a row)."""
    IK_FAILURE = "ik_failure"
    """The IK found no solution for longer than SafetyConfig.ik_hold_ticks ticks in a row, or before
    any good reference existed."""
    ESTOP = "estop"


@dataclass(frozen=True)
class SafetyEvent:
    t_s: float
    kind: SafetyEventKind
    detail: str
    trips: bool
    """True when the event switched the robot to damping for good."""
    planned: bool = False
    """A planned ending (operator stop, end of the control time, a signal): logged at INFO, not as an error."""

    def __str__(self) -> str:
        return f"[{self.t_s:.3f} s] {self.kind.value}{' (damping)' if self.trips else ''}: {self.detail}"
