"""Unitree's MuJoCo simulator (unitree_mujoco) as the emulator plays it (`g1 sim-robot --mode
unitree_mujoco`), so `g1 deploy` with backend.simulator: unitree_mujoco is tested without it (its
source cannot be fetched in CI). Its traits (docs: g1_control/hardware/unitree/simulators.py):

  LowState_    crc, tick and mode_machine left at 0, published at its physics rate (200 Hz)
  LowCmd_      taken whatever its CRC and mode_machine
  motor law    tau = tau + kp (q - q_meas) + kd (dq - dq_meas), computed when a LowCmd_ arrives
               from the state then, and held until the next one (not re-evaluated every physics step)
  no motion service (nothing to release; the host must not wait for one)

The physics steps at 5 ms (its SIMULATE_DT), one step per LowState_.
"""

from __future__ import annotations

import numpy as np

from g1_control.hardware.unitree.simulators import SIMULATORS
from g1_control.sim.mujoco_backend import MujocoBackend, MujocoConfig
from g1_control.types import MotorCommand

PROFILE = SIMULATORS["unitree_mujoco"]
PHYSICS_DT_S = 1.0 / PROFILE.state_rate_hz
"""unitree_mujoco's SIMULATE_DT (0.005 s shipped)."""


class HeldTorqueMujoco(MujocoBackend):
    """MuJoCo with unitree_mujoco's motor law: the PD torque of a command is computed once, when the
    command arrives (write_command), from the joints' state then, and held as a plain torque until
    the next command; a disabled motor gives none."""

    def __init__(self, config: MujocoConfig | None = None, **kwargs):
        super().__init__(config or MujocoConfig(physics_dt_s=PHYSICS_DT_S), **kwargs)

    def write_command(self, command: MotorCommand) -> None:
        q, dq = self.data.qpos[self._q], self.data.qvel[self._v]
        tau = command.tau_nm + command.kp * (command.q_rad - q) + command.kd * (command.dq_radps - dq)
        super().write_command(MotorCommand(q_rad=np.array(q), tau_nm=tau, enable=command.enable.copy()))


__all__ = ["PHYSICS_DT_S", "PROFILE", "HeldTorqueMujoco"]
