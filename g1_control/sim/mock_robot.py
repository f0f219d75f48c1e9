"""MockG1: a stand-in for the robot's motors where hardware is absent (tests, bench, CAN/serial rigs).

Each joint is a rotor-plus-link inertia driven by the robot's motor law, saturated at the joint's
effort limit, capped at its motor's speed limit and stopped at its position limits; the base never moves (the robot hangs on a
gantry). It is not a simulator of the G1 (that is the MuJoCo backend); it gives transports and the
safety layer something physical-looking to close the loop on.
"""

from __future__ import annotations

import numpy as np

from g1_control.interfaces import Backend
from g1_control.robot import g1
from g1_control.types import MotorCommand, RobotState

LINK_INERTIA_KGM2 = 0.05
"""Nominal link inertia seen by every joint (rough; only the order of magnitude matters here)."""


class MockG1(Backend):
    lockstep = True

    def __init__(self, mode_machine: int = 5, temperature_c: float = 35.0):
        self.mode_machine = mode_machine
        self.temperature_c = temperature_c
        self._inertia = g1.ARMATURE_KGM2 + LINK_INERTIA_KGM2
        self._command = MotorCommand(enable=np.zeros(g1.NUM_JOINTS, dtype=bool))
        self.reset()

    def reset(self) -> RobotState:
        self._t = 0.0
        self._tick = 0
        self._q = g1.DEFAULT_Q_RAD.copy()
        self._dq = np.zeros(g1.NUM_JOINTS)
        self._tau = np.zeros(g1.NUM_JOINTS)
        self.imu_quat_wxyz = np.array([1.0, 0.0, 0.0, 0.0])
        return self.read_state()

    def read_state(self) -> RobotState:
        return RobotState(
            t_s=self._t, q_rad=self._q.copy(), dq_radps=self._dq.copy(), tau_nm=self._tau.copy(),
            imu_quat_wxyz=self.imu_quat_wxyz.copy(),
            motor_temperature_c=np.full(g1.NUM_JOINTS, self.temperature_c),
            mode_machine=self.mode_machine, tick=self._tick,
        )

    def write_command(self, command: MotorCommand) -> None:
        self._command = command

    def step(self, dt_s: float) -> None:
        c = self._command
        tau = c.tau_nm + c.kp * (c.q_rad - self._q) + c.kd * (c.dq_radps - self._dq)
        tau = np.where(c.enable, np.clip(tau, -g1.EFFORT_LIMIT_NM, g1.EFFORT_LIMIT_NM), 0.0)
        # Semi-implicit Euler; substeps keep stiff gains (kp up to ~500) stable at 2 ms ticks.
        substeps = max(1, int(np.ceil(dt_s / 0.0005)))
        h = dt_s / substeps
        for _ in range(substeps):
            self._dq += h * tau / self._inertia
            # A motor cannot outrun its no-load speed: back-EMF caps it at the family's limit.
            np.clip(self._dq, -g1.VELOCITY_LIMIT_RADPS, g1.VELOCITY_LIMIT_RADPS, out=self._dq)
            self._q += h * self._dq
            hit = (self._q < g1.Q_MIN_RAD) | (self._q > g1.Q_MAX_RAD)
            self._q = np.clip(self._q, g1.Q_MIN_RAD, g1.Q_MAX_RAD)
            self._dq[hit] = 0.0
            tau = c.tau_nm + c.kp * (c.q_rad - self._q) + c.kd * (c.dq_radps - self._dq)
            tau = np.where(c.enable, np.clip(tau, -g1.EFFORT_LIMIT_NM, g1.EFFORT_LIMIT_NM), 0.0)
        self._tau = tau
        self._t += dt_s
        self._tick += 1

    def close(self) -> None:
        self._command = MotorCommand.damping()
