"""Whole-body goal poses: standing at a height with an arm posture, a hand at a point, both hands
on a box. Each is solved once, from a warm start, by continuation (the IK run a few times toward
the same targets), and reached by a joint-space quintic (whole_body.keyframe_trajectory): a
per-sample IK along a straight hand path dithers at the edge of the reach, and the tracker answers
dithering with large internal foot forces (issue 17 investigation).

Reach (arm first): the arm alone (pelvis and trunk held), else crouching and leaning a little
(pelvis down, pitch allowed, both costing more than arm motion), else the whole body; the
first whose hand residual is within REACH_TOLERANCE_M wins, else the closest. A point beyond
MAX_REACH_M from the shoulder, or whose closest pose leaves the hand more than
REFUSE_RESIDUAL_M off, is refused with the distance in the message.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from g1_control.ik.whole_body import LEG_LIGHT_POSTURE_WEIGHT, WholeBodyIK
from g1_control.robot import g1
from g1_control.robot.dynamics import HAND_FRAMES, SOLE_FRAMES
from g1_control.rotations import rot_z

REACH_TOLERANCE_M = 0.01
REFUSE_RESIDUAL_M = 0.03
MAX_REACH_M = 0.58
"""From the shoulder joint (allowed to drop by CROUCH_DROP_M for a low point) to the hand point:
beyond this no standing pose reaches (0.52-0.55 m is the edge in some directions, issue 17
investigation)."""
CROUCH_DROP_M = 0.30
"""Crouching and leaning can lower a shoulder by about this much (pelvis 0.76 -> 0.45 m)."""
PELVIS_CAP_ABOVE_NOMINAL_M = 0.01
"""Poses keep the pelvis at most this above its nominal height: straight knees are singular."""
HAND_FACE_OFFSET_M = 0.045
"""From the hand frame's point to the inner face of the rubber hand (its palm side)."""
SHOULDERS = ("left_shoulder_pitch_joint", "right_shoulder_pitch_joint")
ARMS = np.array(g1.ARM_JOINTS)
WAIST = np.array(g1.WAIST_JOINTS)


class ReachRefused(ValueError):
    """A goal the robot cannot reach from where it stands (the message says why)."""


Sole = tuple[np.ndarray, np.ndarray]


@dataclass
class PoseResult:
    q: np.ndarray
    residual_m: float
    mode: str


def flat_soles(ik: WholeBodyIK, q: np.ndarray) -> list[Sole]:
    """Both soles where they are in `q`, made level (roll and pitch removed, yaw kept)."""
    out = []
    for name in SOLE_FRAMES:
        p, r = ik.frame_pose(q, name)
        out.append((p.copy(), rot_z(np.asarray(math.atan2(r[1, 0], r[0, 0])))))
    return out


def stance_heading(soles: list[Sole]) -> float:
    yaws = [math.atan2(r[1, 0], r[0, 0]) for _, r in soles]
    return math.atan2(sum(math.sin(y) for y in yaws), sum(math.cos(y) for y in yaws))


class PosePlanner:
    def __init__(self, ik: WholeBodyIK | None = None):
        self.ik = ik or WholeBodyIK()
        q = self.ik.nominal()
        self.nominal_pelvis_m = float(q[2])
        soles = flat_soles(self.ik, q)
        mid = (soles[0][0][:2] + soles[1][0][:2]) / 2
        self.com_offset_m = self.ik.com(q)[:2] - mid
        """The standing CoM's place relative to the middle of the soles (heading frame; ~3 cm ahead)."""
        self.mass_kg = float(sum(i.mass for i in self.ik.model.inertias))

    # -- helpers ------------------------------------------------------------------------------
    def com_over(self, soles: list[Sole], shift_h: np.ndarray | None = None) -> np.ndarray:
        """CoM xy over the middle of the soles at its standing offset (+ a shift, heading frame)."""
        h = stance_heading(soles)
        mid = (soles[0][0][:2] + soles[1][0][:2]) / 2
        off = self.com_offset_m + (0.0 if shift_h is None else np.asarray(shift_h))
        c, s = math.cos(h), math.sin(h)
        return mid + np.array([c * off[0] - s * off[1], s * off[0] + c * off[1]])

    def shoulder(self, q: np.ndarray, hand: int) -> np.ndarray:
        ik = self.ik
        ik.pin.forwardKinematics(ik.model, ik.data, q)
        return ik.data.oMi[ik.model.getJointId(SHOULDERS[hand])].translation.copy()

    def hand_point(self, q: np.ndarray, hand: int) -> np.ndarray:
        return self.ik.frame_pose(q, HAND_FRAMES[hand])[0]

    def _solve(self, q, soles, com_xy, pelvis_z, heading, posture, *, rounds=6, **kw) -> np.ndarray:
        for _ in range(rounds):
            q = self.ik.solve(q, soles, com_xy, pelvis_z, rot_z(heading), posture, sole_weight=1000.0,
                              iterations=40, **kw)
        return q

    # -- poses --------------------------------------------------------------------------------
    def stand(self, q0: np.ndarray, soles: list[Sole], pelvis_z: float, posture: np.ndarray,
              com_shift_h: np.ndarray | None = None) -> np.ndarray:
        """Standing on `soles` with the pelvis at pelvis_z (above the lower sole's level, which is
        the world z of the soles here) and the arms/waist at `posture`. Deep heights lean the
        trunk (the ankles reach their dorsiflexion limit below ~0.55 m)."""
        weights = LEG_LIGHT_POSTURE_WEIGHT.copy()
        weights[ARMS] = 5.0
        com, heading = self.com_over(soles, com_shift_h), stance_heading(soles)
        # continuation: a far height in steps, each from the last (one jump from 0.76 to 0.45 m lands
        # in a wrong local solution, straight knees or stuck at the start)
        q = q0
        steps = max(1, math.ceil(abs(pelvis_z - q0[2]) / 0.04))
        for k in range(1, steps + 1):
            z = q0[2] + (pelvis_z - q0[2]) * k / steps
            q = self._solve(q, soles, com, z, heading, posture, posture_weight=weights, com_weight=300.0,
                            pelvis_rot_weight=(10.0, 0.3, 10.0), rounds=8 if k == steps else 2)
        return q

    def reach(self, q0: np.ndarray, soles: list[Sole], hand: int, target_w: np.ndarray,
              posture: np.ndarray | None = None) -> PoseResult:
        """The pose with hand `hand` (0 left, 1 right) at target_w (arm first; module docstring).
        Raises ReachRefused when no standing pose gets within REFUSE_RESIDUAL_M."""
        target_w = np.asarray(target_w, dtype=float)
        shoulder = self.shoulder(q0, hand)
        dist = float(np.linalg.norm(target_w - shoulder))
        # crouching and leaning lower the shoulder by up to CROUCH_DROP_M
        below = max(0.0, shoulder[2] - CROUCH_DROP_M - target_w[2]) if target_w[2] < shoulder[2] else \
            target_w[2] - shoulder[2]
        reach_dist = float(np.hypot(np.linalg.norm(target_w[:2] - shoulder[:2]), below))
        side = ("left", "right")[hand]
        if reach_dist > MAX_REACH_M:
            raise ReachRefused(f"{side} hand: the point is {dist:.2f} m from the shoulder; standing, the hand "
                               f"reaches {MAX_REACH_M:.2f} m at most (step closer first)")
        posture = g1.DEFAULT_Q_RAD.copy() if posture is None else posture
        heading = stance_heading(soles)
        ground = min(s[0][2] for s in soles)
        z_nominal = ground + self.nominal_pelvis_m
        hands = [(HAND_FRAMES[hand], target_w)]
        com = self.com_over(soles)
        best: PoseResult | None = None
        # warm start, then the reaching arm (and then both) from the default pose: a warm start
        # from an arm stretched elsewhere lands in a wrong local solution (measured: 5 cm short)
        seeds = [q0, q0.copy(), q0.copy()]
        arm = np.array(g1.ARM_JOINTS[:7] if hand == 0 else g1.ARM_JOINTS[7:])
        seeds[1][7 + arm] = g1.DEFAULT_Q_RAD[arm]
        seeds[2][7 + ARMS] = g1.DEFAULT_Q_RAD[ARMS]
        modes = (
            # arm only: pelvis height and trunk held
            ("arm_only", dict(pelvis_z=q0[2], posture_weight=_weights(legs=0.002, waist=5.0, arms=0.02),
                              pelvis_rot_weight=(10.0, 10.0, 10.0), pelvis_z_weight=100.0)),
            # crouch / lean: cost more than arm motion
            ("hybrid", dict(pelvis_z=z_nominal, posture_weight=_weights(legs=0.002, waist=0.5, arms=0.02),
                            pelvis_rot_weight=(10.0, 1.0, 5.0), pelvis_z_weight=1.0)),
            ("whole_body", dict(pelvis_z=None, posture_weight=_weights(legs=0.002, waist=0.05, arms=0.02),
                                pelvis_rot_weight=(5.0, 0.3, 2.0), pelvis_z_weight=1.0)),
        )
        for seed in seeds:
            for mode, kw in modes:
                kw = dict(kw)
                pz = kw.pop("pelvis_z")
                q = self._solve(seed, soles, com, pz, heading, posture, hands=hands, hand_weight=100.0, com_weight=300.0,
                                pelvis_z_max=z_nominal + PELVIS_CAP_ABOVE_NOMINAL_M, rounds=8, **kw)
                res = float(np.linalg.norm(self.hand_point(q, hand) - target_w))
                if best is None or res < best.residual_m - 1e-4:
                    best = PoseResult(q, res, mode)
                if res <= REACH_TOLERANCE_M:
                    break
            if best is not None and best.residual_m <= REACH_TOLERANCE_M:
                break
        assert best is not None
        if best.residual_m > REFUSE_RESIDUAL_M:
            raise ReachRefused(f"{side} hand: the closest standing pose leaves the hand {best.residual_m * 100:.1f} cm "
                               f"from the point ({dist:.2f} m from the shoulder)")
        return best

    def hands_on(self, q0: np.ndarray, soles: list[Sole], targets: tuple[np.ndarray, np.ndarray],
                 heading: float, com_shift_h: np.ndarray | None = None) -> PoseResult:
        """Both hands at points (a grasp), palms facing each other across the heading."""
        hands = [(HAND_FRAMES[0], targets[0]), (HAND_FRAMES[1], targets[1])]
        rot = rot_z(np.asarray(heading))
        ground = min(s[0][2] for s in soles)
        z_nominal = ground + self.nominal_pelvis_m
        q = self._solve(q0, soles, self.com_over(soles, com_shift_h), z_nominal, heading, g1.DEFAULT_Q_RAD,
                        hands=hands, hand_weight=100.0, hand_rot=[(HAND_FRAMES[0], rot), (HAND_FRAMES[1], rot)],
                        hand_rot_weight=3.0, pelvis_rot_weight=(10.0, 1.0, 5.0), pelvis_z_weight=1.0,
                        pelvis_z_max=z_nominal + PELVIS_CAP_ABOVE_NOMINAL_M, com_weight=300.0, rounds=10)
        res = max(float(np.linalg.norm(self.hand_point(q, i) - targets[i])) for i in range(2))
        return PoseResult(q, res, "both_hands")


def _weights(legs: float, waist: float, arms: float) -> np.ndarray:
    w = np.full(g1.NUM_JOINTS, legs)
    w[WAIST] = waist
    w[ARMS] = arms
    return w


__all__ = ["HAND_FACE_OFFSET_M", "MAX_REACH_M", "PosePlanner", "PoseResult", "ReachRefused", "flat_soles",
           "stance_heading"]
