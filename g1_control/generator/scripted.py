"""Scripted whole-body references for the WBC's tests and figures.

Each builder returns a WholeBodyTrajectory (generator/whole_body.py): root pose, joint angles and
the contact schedule sampled in time, played back through cubic splines. Poses that must keep the
feet planted or put a hand somewhere come from the whole-body IK (ik/whole_body.py: WholeBodyIK,
joint limits inside its iteration); stepping references take their CoM from ZMP preview control over a footstep plan
(zmp_preview.py).

    stand          the default pose, still
    arm_wave       both arms swinging in antiphase (shoulder pitch +-0.6 rad, elbows, 0.5 Hz)
    crouch         pelvis down 15 cm and back up, feet planted
    lean_reach     right hand to a point 0.5 m ahead of the pelvis's start, leaning, and back
    step_in_place  eight steps on the spot (5 cm foot lift)
    walk           straight walk at 0.3 m/s

In the loop: a launch file with `generator: {type: scripted, reference: NAME}` (g1_control/launch/builder.py).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from g1_control.errors import WbcConfigError
from g1_control.generator.whole_body import WholeBodyTrajectory, smoothstep, trajectory_from_configurations
from g1_control.generator.zmp_preview import ZmpPreviewController
from g1_control.ik.whole_body import WholeBodyIK
from g1_control.interfaces import Generator
from g1_control.robot import g1
from g1_control.robot.dynamics import SOLE_FRAMES
from g1_control.types import Command, JointReference, KinematicReference, RobotState

_trajectory = trajectory_from_configurations


class TrajectoryGenerator(Generator):
    """Plays a trajectory as the generator stage (time from the robot state's clock). The trajectory
    is feasible by construction: each reference carries its sample (with the exact joint
    velocities a KinematicReference does not hold) as the feasible plan the IK stage passes on."""

    def __init__(self, trajectory: WholeBodyTrajectory):
        self.trajectory = trajectory
        self._joint = JointReference()
        self._ref = KinematicReference()
        self._t0 = 0.0

    def reset(self, state: RobotState) -> None:
        self._t0 = state.t_s

    def update(self, command: Command, state: RobotState) -> KinematicReference:
        j = self.trajectory.sample(state.t_s - self._t0, self._joint)
        ref = self._ref.set_from(j)
        ref.t_s = state.t_s - self._t0
        return ref


# -- the references ------------------------------------------------------------------------------------------
def stand(duration_s: float = 60.0, variant: str = "g1_29dof") -> WholeBodyTrajectory:
    q0 = WholeBodyIK(g1.variant_named(variant)).nominal()
    t = np.array([0.0, duration_s])
    return _trajectory("stand", t, np.array([q0, q0]), np.ones((2, 2), dtype=bool))


def arm_wave(duration_s: float = 10.0, frequency_hz: float = 0.5, amplitude_rad: float = 0.6,
             variant: str = "g1_29dof") -> WholeBodyTrajectory:
    q0 = WholeBodyIK(g1.variant_named(variant)).nominal()
    t = np.arange(0.0, duration_s + 1e-9, 0.01)
    qs = np.repeat(q0[None], len(t), axis=0)
    ramp = smoothstep(t / 1.0) * smoothstep((duration_s - t) / 1.0)
    phase = 2 * np.pi * frequency_hz * t
    j = g1.JOINT_INDEX
    for side, sign in (("left", 1.0), ("right", -1.0)):
        qs[:, 7 + j[f"{side}_shoulder_pitch_joint"]] += ramp * amplitude_rad * sign * np.sin(phase)
        qs[:, 7 + j[f"{side}_elbow_joint"]] += ramp * 0.4 * sign * np.sin(phase + 0.5)
        qs[:, 7 + j[f"{side}_shoulder_roll_joint"]] += ramp * 0.3 * (1 if side == "left" else -1) * (1 - np.cos(phase)) / 2
    return _trajectory("arm_wave", t, qs, np.ones((len(t), 2), dtype=bool))


def _planted_feet(ik: WholeBodyIK, q0: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
    return [ik.frame_pose(q0, name) for name in SOLE_FRAMES]


def crouch(depth_m: float = 0.15, down_s: float = 2.0, hold_s: float = 1.5, variant: str = "g1_29dof") -> WholeBodyTrajectory:
    ik = WholeBodyIK(g1.variant_named(variant))
    q0 = ik.nominal()
    soles = _planted_feet(ik, q0)
    com_xy = ik.com(q0)[:2]
    t_events = np.cumsum([1.0, down_s, hold_s, down_s, hold_s])
    t = np.arange(0.0, t_events[-1] + 1e-9, 0.02)
    drop = depth_m * (smoothstep((t - t_events[0]) / down_s) - smoothstep((t - t_events[2]) / down_s))
    qs, q = [], q0
    for dz in drop:
        q = ik.solve(q, soles, com_xy, q0[2] - dz, np.eye(3), g1.DEFAULT_Q_RAD, iterations=8)
        qs.append(q)
    return _trajectory("crouch", t, np.array(qs), np.ones((len(t), 2), dtype=bool), depth_m=depth_m)


def lean_reach(ahead_m: float = 0.5, height_m: float = 0.8, side_m: float = -0.2,
               reach_s: float = 2.5, hold_s: float = 2.0, variant: str = "g1_29dof") -> WholeBodyTrajectory:
    """Right hand to (ahead_m, side_m, height_m) in the start pelvis's ground frame, CoM kept over
    the feet (the hips move back as the torso leans), then back to the default pose."""
    ik = WholeBodyIK(g1.variant_named(variant))
    q0 = ik.nominal()
    soles = _planted_feet(ik, q0)
    com_xy = ik.com(q0)[:2]
    hand0, _ = ik.frame_pose(q0, "right_hand")
    target = np.array([ahead_m, side_m, height_m])
    t_events = np.cumsum([1.0, reach_s, hold_s, reach_s, 1.0])
    t = np.arange(0.0, t_events[-1] + 1e-9, 0.02)
    s = smoothstep((t - t_events[0]) / reach_s) - smoothstep((t - t_events[2]) / reach_s)
    qs, q = [], q0
    for sk in s:
        goal = hand0 + sk * (target - hand0)
        q = ik.solve(q, soles, com_xy, None, np.eye(3), g1.DEFAULT_Q_RAD, hands=[("right_hand", goal)], hand_weight=100.0,
                     pelvis_rot_weight=(10.0, 0.5, 10.0), posture_weight=0.05, iterations=10)
        qs.append(q)
    achieved, _ = ik.frame_pose(qs[int(np.argmax(s))], "right_hand")
    return _trajectory("lean_reach", t, np.array(qs), np.ones((len(t), 2), dtype=bool), hand_target_w_m=target,
                       hand_reference_w_m=achieved, hold_window_s=(float(t_events[1]), float(t_events[2])))


def stepping(footsteps: list[tuple[int, np.ndarray]], *, single_support_s: float = 0.4,
             double_support_s: float = 0.15, lift_m: float = 0.05, start_s: float = 1.0, end_s: float = 1.5,
             pelvis_drop_m: float = 0.02, name: str = "stepping", dt_s: float = 0.01,
             variant: str = "g1_29dof") -> WholeBodyTrajectory:
    """Footsteps (foot index 0 left / 1 right, new sole xy) taken one after another; CoM from
    ZMP preview control, ZMP on the stance sole during single support and moving linearly
    between soles during double support."""
    ik = WholeBodyIK(g1.variant_named(variant))
    q0 = ik.nominal()
    soles0 = _planted_feet(ik, q0)
    com0 = ik.com(q0)
    offset_xy = com0[:2] - (soles0[0][0][:2] + soles0[1][0][:2]) / 2  # CoM over the feet, as standing
    step_period = single_support_s + double_support_s
    total = start_s + len(footsteps) * step_period + double_support_s + end_s
    t = np.arange(0.0, total + 1e-9, dt_s)
    n = len(t)
    feet = np.zeros((n, 2, 3))
    feet[:] = [soles0[0][0], soles0[1][0]]
    contacts = np.ones((n, 2), dtype=bool)
    zmp = np.zeros((n, 2))
    current = [soles0[0][0].copy(), soles0[1][0].copy()]
    zmp[:] = com0[:2]
    prev_zmp = com0[:2].copy()
    t0 = start_s
    for swing, target_xy in footsteps:
        stance = 1 - swing
        stance_zmp = current[stance][:2] + offset_xy
        ds = (t >= t0) & (t < t0 + double_support_s)
        zmp[ds] = prev_zmp + ((t[ds] - t0) / double_support_s)[:, None] * (stance_zmp - prev_zmp)
        ss = (t >= t0 + double_support_s) & (t < t0 + step_period)
        zmp[ss] = stance_zmp
        tau = (t[ss] - t0 - double_support_s) / single_support_s
        start, goal = current[swing].copy(), np.array([target_xy[0], target_xy[1], current[swing][2]])
        feet[ss, swing] = start + smoothstep(tau)[:, None] * (goal - start)
        feet[ss, swing, 2] += lift_m * (1 - np.cos(2 * np.pi * tau)) / 2
        contacts[ss, swing] = False
        after = t >= t0 + step_period
        feet[after, swing] = goal
        current[swing] = goal
        zmp[after] = stance_zmp
        prev_zmp = stance_zmp
        t0 += step_period
    final_zmp = (current[0][:2] + current[1][:2]) / 2 + offset_xy
    ds = t >= t0
    zmp[ds] = prev_zmp + np.clip((t[ds] - t0) / double_support_s, 0, 1)[:, None] * (final_zmp - prev_zmp)
    # The pelvis lowers during the initial stand, so the first sample is the nominal pose.
    pelvis_z = q0[2] - pelvis_drop_m * smoothstep(t / start_s)
    preview = ZmpPreviewController(dt_s, com0[2] - pelvis_drop_m)
    com_xy, _, _ = preview.plan(zmp, com0[:2])
    rot0 = soles0[0][1]
    qs, q = [], q0
    for k in range(n):
        q = ik.solve(q, [(feet[k, 0], rot0), (feet[k, 1], rot0)], com_xy[k], pelvis_z[k], np.eye(3),
                     g1.DEFAULT_Q_RAD, iterations=6 if k else 30)
        qs.append(q)
    return _trajectory(name, t, np.array(qs), contacts, zmp_ref_xy_m=zmp, com_plan_xy_m=com_xy,
                       feet_w_m=feet)


def step_in_place(n_steps: int = 8, **kw) -> WholeBodyTrajectory:
    ik = WholeBodyIK()
    q0 = ik.nominal()
    soles = _planted_feet(ik, q0)
    steps = [(k % 2, soles[k % 2][0][:2].copy()) for k in range(n_steps)]
    return stepping(steps, name="step_in_place", **kw)


def walk(speed_mps: float = 0.3, n_steps: int = 12, single_support_s: float = 0.4,
         double_support_s: float = 0.15, **kw) -> WholeBodyTrajectory:
    """Walk straight ahead at `speed_mps` (step length = speed x step period), then close the feet."""
    ik = WholeBodyIK()
    q0 = ik.nominal()
    soles = _planted_feet(ik, q0)
    step = speed_mps * (single_support_s + double_support_s)
    steps = []
    for k in range(n_steps):
        foot = k % 2
        x = soles[foot][0][0] + step * (k + 1)
        steps.append((foot, np.array([x, soles[foot][0][1]])))
    last = n_steps % 2  # bring the trailing foot alongside
    steps.append((last, np.array([steps[-1][1][0], soles[last][0][1]])))
    return stepping(steps, single_support_s=single_support_s, double_support_s=double_support_s,
                    name="walk", **kw)


REFERENCES: dict[str, Callable[[], WholeBodyTrajectory]] = {
    "stand": stand,
    "arm_wave": arm_wave,
    "crouch": crouch,
    "lean_reach": lean_reach,
    "step_in_place": step_in_place,
    "walk": walk,
}


def build_reference(name: str, **kw) -> WholeBodyTrajectory:
    if name not in REFERENCES:
        raise WbcConfigError(f"unknown WBC reference '{name}'; known: {', '.join(REFERENCES)}")
    return REFERENCES[name](**kw)
