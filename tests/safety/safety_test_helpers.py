"""States and commands shared by the safety tests."""

from __future__ import annotations

import numpy as np

from g1_control.robot import g1
from g1_control.types import MotorCommand, RobotState


def state(t_s=0.0, tick=None, **kw) -> RobotState:
    """A healthy robot at the default pose, 40 °C. By default every state is a new sample (its tick
    follows its time, 2 ms per robot tick)."""
    tick = round(t_s * 500) if tick is None else tick
    return RobotState(t_s=t_s, q_rad=g1.DEFAULT_Q_RAD.copy(), motor_temperature_c=np.full(29, 40.0), tick=tick, **kw)


def command(**kw) -> MotorCommand:
    """The default pose at the default gains; `kw` replaces or adds fields."""
    return MotorCommand(**{"q_rad": g1.DEFAULT_Q_RAD.copy(), "kp": g1.KP_DEFAULT.copy(), "kd": g1.KD_DEFAULT.copy(),
                           **kw})
