"""Unitree's MuJoCo simulator (unitree_mujoco) as the emulator plays it (`g1 sim-robot --mode
unitree_mujoco`), so `g1 deploy` with backend.simulator: unitree_mujoco is tested without it (its
source cannot be fetched in CI). Its traits (docs: g1_control/hardware/unitree/simulators.py):

  LowState_    crc, tick and mode_machine left at 0, published at its physics rate (200 Hz)
  LowCmd_      taken whatever its CRC and mode_machine
  motor law    tau = tau + kp (q - q_meas) + kd (dq - dq_meas), computed when a LowCmd_ arrives
               from the state then, and held until the next one (not re-evaluated every physics step)
  no motion service (nothing to release; the host must not wait for one)
  joints       passive damping and friction on every joint, as its G1 model sets them

The physics steps at 5 ms (its SIMULATE_DT), one step per LowState_.

Its G1 model (unitree_robots/g1/g1_29dof.xml) gives every joint damping 0.05 N m s/rad and a
friction loss of 0.2 N m (the wrists 0.1): what stills a G1 hanging limp in its elastic band before
a host commands it (a held torque of 0, no motor damping). Without them the limp arms swung for
good at up to 10 rad/s, and at 5 ms steps every strike of a stop went 0.02-0.05 rad past it.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from g1_control.hardware.unitree.simulators import SIMULATORS
from g1_control.robot import g1
from g1_control.sim.mujoco_backend import MujocoBackend, MujocoConfig
from g1_control.types import MotorCommand

PROFILE = SIMULATORS["unitree_mujoco"]
PHYSICS_DT_S = 1.0 / PROFILE.state_rate_hz
"""unitree_mujoco's SIMULATE_DT (0.005 s shipped)."""
JOINT_DAMPING_NMS_PER_RAD = 0.05
JOINT_FRICTION_NM = 0.2
WRIST_FRICTION_NM = 0.1
"""Passive joint damping and friction loss of unitree_mujoco's G1 model (see above)."""


class HeldTorqueMujoco(MujocoBackend):
    """MuJoCo with unitree_mujoco's motor law: the PD torque of a command is computed once, when the
    command arrives (write_command), from the joints' state then, and held as a plain torque until
    the next command; a disabled motor gives none. Its joints have that simulator's passive damping
    and friction (JOINT_DAMPING_NMS_PER_RAD, JOINT_FRICTION_NM), and hard stops (the emulated robot's)."""

    def __init__(self, config: MujocoConfig | None = None, **kwargs):
        config = config or MujocoConfig(physics_dt_s=PHYSICS_DT_S)
        super().__init__(dataclasses.replace(config, hard_joint_stops=True), **kwargs)
        wrist = np.array(["_wrist_" in g1.JOINT_NAMES[i] for i in self._active])
        self.model.dof_damping[self._v] = JOINT_DAMPING_NMS_PER_RAD
        self.model.dof_frictionloss[self._v] = np.where(wrist, WRIST_FRICTION_NM, JOINT_FRICTION_NM)

    def write_command(self, command: MotorCommand) -> None:
        q, dq = self.data.qpos[self._q], self.data.qvel[self._v]
        tau = command.tau_nm + command.kp * (command.q_rad - q) + command.kd * (command.dq_radps - dq)
        super().write_command(MotorCommand(q_rad=np.array(q), tau_nm=tau, enable=command.enable.copy()))


__all__ = ["JOINT_DAMPING_NMS_PER_RAD", "JOINT_FRICTION_NM", "PHYSICS_DT_S", "PROFILE", "WRIST_FRICTION_NM",
           "HeldTorqueMujoco"]
