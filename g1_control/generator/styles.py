"""Upper-body styles the library records in physics and the generator can be asked for.

A style is a waist+arm posture (offsets from g1.DEFAULT_Q_RAD), optionally with a periodic
component. Rollout styles are tracked by the locomotion policy with its upper-body override, so
every recorded frame was balanced by the legs in MuJoCo: that is what keeps the variants
physically plausible (a pose the policy cannot balance shows up as a fall and is dropped).
Data styles ("dance", "climb", "lift") come from clips, not from these poses.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from g1_control.robot import g1


def _q(**offsets: float) -> dict[str, float]:
    return {f"{k}_joint": v for k, v in offsets.items()}


@dataclass(frozen=True)
class UpperBodyStyle:
    name: str
    offsets: dict[str, float] = field(default_factory=dict)
    """Joint name -> offset (rad) from the default pose."""
    wave: dict[str, float] = field(default_factory=dict)
    """Joint name -> amplitude (rad) of a sine at wave_hz."""
    wave_hz: float = 0.0
    override: bool = True
    """False: the policy's own arms (the 'default' style)."""

    def pose(self, t_s: float) -> np.ndarray:
        """Whole-body posture (29,) at time t_s; legs at the default pose."""
        q = g1.DEFAULT_Q_RAD.copy()
        for name, off in self.offsets.items():
            q[g1.JOINT_INDEX[name]] += off
        if self.wave_hz > 0:
            s = np.sin(2 * np.pi * self.wave_hz * t_s)
            for name, amp in self.wave.items():
                q[g1.JOINT_INDEX[name]] += amp * s
        return np.clip(q, g1.Q_MIN_RAD, g1.Q_MAX_RAD)


# Sign conventions (G1 description): shoulder pitch < 0 lifts the arm forward; left shoulder
# roll > 0 lifts the left arm sideways (right arm mirrored); elbow > 0 bends.
ROLLOUT_STYLES: dict[str, UpperBodyStyle] = {s.name: s for s in (
    UpperBodyStyle("default", override=False),
    UpperBodyStyle("carry", _q(left_shoulder_pitch=-0.75, right_shoulder_pitch=-0.75, left_shoulder_roll=-0.1,
                               right_shoulder_roll=0.1, left_elbow=0.3, right_elbow=0.3)),
    UpperBodyStyle("arms_out", _q(left_shoulder_roll=1.1, right_shoulder_roll=-1.1, left_elbow=-0.5,
                                  right_elbow=-0.5)),
    UpperBodyStyle("wave", _q(right_shoulder_pitch=-1.6, right_shoulder_roll=-0.5, right_elbow=0.2),
                   wave=_q(right_elbow=0.45, right_shoulder_roll=-0.25), wave_hz=1.2),
    UpperBodyStyle("guard", _q(left_shoulder_pitch=-0.6, right_shoulder_pitch=-0.6, left_shoulder_roll=0.1,
                               right_shoulder_roll=-0.1, left_elbow=0.9, right_elbow=0.9)),
    UpperBodyStyle("arm_swing", _q(left_elbow=0.3, right_elbow=0.3),
                   wave=_q(left_shoulder_pitch=0.55, right_shoulder_pitch=-0.55), wave_hz=1.0),
    # Arms straight overhead (shoulder pitch -2.1) tipped the robot over within 3 s in every
    # rollout tried; reaching forward-up at about 60 degrees is what the policy can balance.
    UpperBodyStyle("reach_up", _q(left_shoulder_pitch=-1.25, right_shoulder_pitch=-1.25, left_elbow=-0.35,
                                  right_elbow=-0.35)),
    UpperBodyStyle("look_around", _q(), wave=_q(waist_yaw=0.5), wave_hz=0.3),
)}

DATA_STYLES = ("dance", "climb", "lift")
STYLES: tuple[str, ...] = tuple(ROLLOUT_STYLES) + DATA_STYLES
"""Every style label the library and the generator know, in a fixed order (the model's style ids)."""


def style_id(name: str) -> int:
    try:
        return STYLES.index(name)
    except ValueError:
        raise ValueError(f"unknown style '{name}'; known styles: {', '.join(STYLES)}") from None
