"""Styled walking on a velocity-command walking policy: the plan drives the upper body while the
policy keeps balancing with the legs, and the legs crouch to a planned pelvis height.

Why this shape (measured in MuJoCo before this tracker existed): the holosoma walking policy was trained
with its own arms and waist. Forcing a plan's arm pose on its motors while it observes them far
from where it keeps them cost 45-100 % of the commanded speed; with the pose forced and no one
compensating the upper body's gravity, the waist pitch sagged to its 0.52 rad limit. Per tick,
while the reference asks for the upper-body override:

  the policy observes   its arms at the default pose at rest (dof_pos 0, dof_vel 0: where it keeps
                        its own arms while walking, within 0.02 rad), its waist shifted back by the
                        waist offsets below, its legs as they are (minus the crouch);
  the motors follow     the plan on the arms (q* = plan, dq* = the plan's velocity, tau = inverse
                        dynamics of the plan's motion: pinocchio RNEA with the IMU's base
                        orientation, the base held still, rotor armature included); the waist
                        = the policy's targets + offsets: yaw the plan's, roll/pitch a lean that
                        takes back half of the centre-of-mass shift of the plan's arms (ComBalance;
                        the plan's own roll/pitch are ignored: the policy balances with them);
                        legs the policy's.

The crouch: hip pitch -a, knee +2a, ankle pitch -a on the policy's leg targets (pelvis level,
feet flat), the policy observing its legs shifted back by the same offset. `a` starts from the
leg kinematics' answer for the planned height and an integral on the estimator's pelvis height
removes the rest (the policy bends a little more than its targets: 0.125 m lower for a = 0.3
measured walking, 0.088 m by kinematics).

Everything here runs every tracker tick without allocating (slices, preallocated buffers).
"""

from __future__ import annotations

import numpy as np

from g1_control.robot import description, g1
from g1_control.types import MotorCommand

ARMS = slice(g1.ARM_JOINTS[0], g1.ARM_JOINTS[-1] + 1)
LEGS = slice(0, len(g1.LEG_JOINTS))
WAIST = slice(g1.WAIST_JOINTS[0], g1.WAIST_JOINTS[-1] + 1)
WAIST_YAW = g1.JOINT_INDEX["waist_yaw_joint"]
_NV_BASE = 6
"""Pinocchio's free-flyer velocity rows before the joints."""

CROUCH_DIRECTION = np.zeros(g1.NUM_JOINTS)
"""Leg offsets per radian of crouch: hip pitch -1, knee +2, ankle pitch -1 (pelvis level, feet flat)."""
for _side in ("left", "right"):
    CROUCH_DIRECTION[g1.JOINT_INDEX[f"{_side}_hip_pitch_joint"]] = -1.0
    CROUCH_DIRECTION[g1.JOINT_INDEX[f"{_side}_knee_joint"]] = 2.0
    CROUCH_DIRECTION[g1.JOINT_INDEX[f"{_side}_ankle_pitch_joint"]] = -1.0


class PlanInverseDynamics:
    """Joint torques that make the joints follow a planned motion: RNEA at (q, dq, ddq) with the
    base's orientation from the IMU and the base held still (its own motion is the legs' job).
    Rotor armature is part of the model, so the result equals MuJoCo's inverse dynamics."""

    def __init__(self):
        import pinocchio as pin

        self._rnea = pin.rnea
        self.model = description.pinocchio_model()
        self.model.armature[_NV_BASE:] = g1.ARMATURE_KGM2
        self.data = self.model.createData()
        self.q = np.zeros(self.model.nq)
        self.v = np.zeros(self.model.nv)
        self.a = np.zeros(self.model.nv)

    def __call__(self, quat_wxyz: np.ndarray) -> np.ndarray:
        """Torques (nv,) for the joint positions/velocities/accelerations already written into
        `joint_q`, `joint_v`, `joint_a`; rows 6: are the joints."""
        q = self.q
        q[3], q[4], q[5], q[6] = quat_wxyz[1], quat_wxyz[2], quat_wxyz[3], quat_wxyz[0]
        return self._rnea(self.model, self.data, q, self.v, self.a)

    @property
    def joint_q(self) -> np.ndarray:
        return self.q[7:]

    @property
    def joint_v(self) -> np.ndarray:
        return self.v[_NV_BASE:]

    @property
    def joint_a(self) -> np.ndarray:
        return self.a[_NV_BASE:]


class ComBalance:
    """The waist lean that takes back a fraction of the centre-of-mass shift a plan's arm posture
    causes. The policy balances a robot whose centre of mass sits where its own arms keep it; arms
    held forward (reach_up: +3.1 cm) made it drift 0.26 m/s forward on a sideways command
    (measured). Leaning the torso back by half the shift removed the drift (fractions 0.3/0.5/0.7
    measured: reach_up sideways 0.178/0.194/0.201 m/s for 0.2 asked, upper body 0.032/0.046/0.064
    rad RMS from the plan; 0.5 kept)."""

    def __init__(self, default_q_rad: np.ndarray, fraction: float = 0.5, max_rad: float = 0.3):
        import pinocchio as pin

        self._com = pin.centerOfMass
        self.fraction = fraction
        self.max_rad = max_rad
        self.model = description.pinocchio_model()
        self.data = self.model.createData()
        self._roll_joint = self.model.getJointId("waist_roll_joint")
        self._pitch_joint = self.model.getJointId("waist_pitch_joint")
        self._mass = float(sum(inertia.mass for inertia in self.model.inertias))
        self.q = np.zeros(self.model.nq)
        self.q[6] = 1.0
        self.q[7:] = default_q_rad
        self._default_q = default_q_rad
        self._com_default = self._com(self.model, self.data, self.q).copy()
        self.roll_rad = 0.0
        self.pitch_rad = 0.0

    def update(self, plan_q: np.ndarray) -> None:
        """The lean (roll_rad, pitch_rad) for the plan's arms and waist yaw, legs and waist roll/pitch
        at the default pose, pelvis upright."""
        joints = self.q[7:]
        joints[ARMS] = plan_q[ARMS]
        joints[WAIST_YAW] = plan_q[WAIST_YAW]
        com = self._com(self.model, self.data, self.q, True)  # with the subtrees' centres of mass
        d = self.data
        shift_x = com[0] - self._com_default[0]
        shift_y = com[1] - self._com_default[1]
        # d(com)/d(angle) = m_subtree / m * R (axis x c_subtree), with the subtree's centre of mass
        # c_subtree in its joint's frame (pinocchio's data.com[j]) and R that frame's rotation.
        c = d.com[self._pitch_joint]  # pitch axis y: y x c = (c_z, 0, -c_x)
        rot = d.oMi[self._pitch_joint].rotation
        dx_dpitch = d.mass[self._pitch_joint] / self._mass * (rot[0, 0] * c[2] - rot[0, 2] * c[0])
        c = d.com[self._roll_joint]  # roll axis x: x x c = (0, -c_z, c_y)
        rot = d.oMi[self._roll_joint].rotation
        dy_droll = d.mass[self._roll_joint] / self._mass * (-rot[1, 1] * c[2] + rot[1, 2] * c[1])
        lim = self.max_rad
        self.pitch_rad = min(max(-self.fraction * shift_x / dx_dpitch, -lim), lim)
        self.roll_rad = min(max(-self.fraction * shift_y / dy_droll, -lim), lim)


class PlannedUpperBody:
    """The upper-body override: what the policy observes and what the motors get (see the module
    docstring). `begin()` once per tick with the reference posture, then `observation()` before
    the policy runs and `command()` after it."""

    def __init__(self, default_q_rad: np.ndarray, dt_s: float):
        self.default_q = default_q_rad
        self.dt_s = dt_s
        self.dynamics = PlanInverseDynamics()
        self.balance = ComBalance(default_q_rad)
        self._plan_q = np.zeros(g1.NUM_JOINTS)
        self._plan_v = np.zeros(g1.NUM_JOINTS)
        self._plan_a = np.zeros(g1.NUM_JOINTS)
        self._prev_v = np.zeros(g1.NUM_JOINTS)
        self.waist_offset = np.zeros(3)
        """(yaw, roll, pitch) added to the policy's waist targets and taken off what it observes:
        the plan's yaw, the balancing lean (ComBalance) on roll and pitch."""
        self.active = False

    def reset(self) -> None:
        self.active = False

    def begin(self, plan_q: np.ndarray) -> None:
        """This tick's plan posture: its velocity and acceleration by finite differences (zero on
        the first tick of an override)."""
        if self.active:
            np.subtract(plan_q, self._plan_q, out=self._plan_v)
            self._plan_v /= self.dt_s
            np.subtract(self._plan_v, self._prev_v, out=self._plan_a)
            self._plan_a /= self.dt_s
        else:
            self._plan_v[:] = 0.0
            self._plan_a[:] = 0.0
        self._prev_v[:] = self._plan_v
        self._plan_q[:] = plan_q
        self.balance.update(plan_q)
        w = self.waist_offset
        w[0] = plan_q[WAIST_YAW] - self.default_q[WAIST_YAW]
        w[1] = self.balance.roll_rad
        w[2] = self.balance.pitch_rad
        self.active = True

    def observation(self, dof_pos: np.ndarray, dof_vel: np.ndarray) -> None:
        """Edit the policy's observed dof_pos (q - default) and dof_vel in place."""
        dof_pos[ARMS] = 0.0
        dof_vel[ARMS] = 0.0
        dof_pos[WAIST] -= self.waist_offset

    def command(self, out: MotorCommand, imu_quat_wxyz: np.ndarray, q_rad: np.ndarray) -> None:
        """Edit the policy's motor command in place: arms on the plan with inverse-dynamics
        feed-forward, the waist shifted by the plan's yaw and the balancing lean."""
        out.q_rad[ARMS] = self._plan_q[ARMS]
        out.dq_radps[ARMS] = self._plan_v[ARMS]
        out.q_rad[WAIST] += self.waist_offset
        out.dq_radps[WAIST_YAW] = self._plan_v[WAIST_YAW]
        dyn = self.dynamics
        jq, jv, ja = dyn.joint_q, dyn.joint_v, dyn.joint_a
        jq[:] = q_rad
        jq[ARMS] = self._plan_q[ARMS]
        jv[ARMS] = self._plan_v[ARMS]
        ja[ARMS] = self._plan_a[ARMS]
        tau = dyn(imu_quat_wxyz)
        out.tau_nm[ARMS] = tau[_NV_BASE + ARMS.start:_NV_BASE + ARMS.stop]


class Crouch:
    """Leg offsets that put the pelvis at a planned height (module docstring)."""

    def __init__(self, default_q_rad: np.ndarray, dt_s: float, max_rad: float = 0.35, ki: float = 2.0,
                 max_rate_radps: float = 0.5, height_filter_tau_s: float = 0.5):
        self.dt_s = dt_s
        self.max_rad = max_rad
        self.ki = ki
        self._step = max_rate_radps * dt_s
        self._alpha = dt_s / (height_filter_tau_s + dt_s)
        self._table_a = np.linspace(0.0, max_rad, 15)
        heights = leg_heights_m(default_q_rad + self._table_a[:, None] * CROUCH_DIRECTION)
        self._table_drop = heights[0] - heights
        self.straight_m = float(heights[0])
        """Pelvis height above the soles with straight (default) legs, by kinematics."""
        self.offset = np.zeros(g1.NUM_JOINTS)
        """The leg offsets of this tick (added to the policy's targets, subtracted from what it observes)."""
        self.angle_rad = 0.0
        self._integral = 0.0
        self._height: float | None = None

    def reset(self) -> None:
        self.offset[:] = 0.0
        self.angle_rad = self._integral = 0.0
        self._height = None

    def update(self, target_m: float | None, measured_m: float | None) -> None:
        """target_m: the planned pelvis height (None: the policy's own height, no crouch);
        measured_m: the estimator's pelvis height (None: unknown, kinematics only)."""
        height = self._height
        if measured_m is not None:
            height = self._height = measured_m if height is None else height + self._alpha * (measured_m - height)
        a = self.angle_rad
        if target_m is None:
            goal = self._integral = 0.0
        else:
            a_ff = float(np.interp(self.straight_m - target_m, self._table_drop, self._table_a))
            settled = abs(a_ff + self._integral - a) <= self._step
            if settled and measured_m is not None and height is not None:
                self._integral += self.ki * (height - target_m) * self.dt_s
            goal = min(max(a_ff + self._integral, 0.0), self.max_rad)
            self._integral = goal - a_ff  # no wind-up beyond the reachable range
        if goal == a:
            return
        self.angle_rad = a + min(max(goal - a, -self._step), self._step)  # rate-limited: no jumps in the legs
        np.multiply(CROUCH_DIRECTION, self.angle_rad, out=self.offset)


def leg_heights_m(postures: np.ndarray) -> np.ndarray:
    """Pelvis height above the lower sole for each joint posture (n, 29), pelvis upright (leg kinematics)."""
    import pinocchio as pin

    from g1_control.estimation.estimator import SOLE_OFFSET_M

    model = description.pinocchio_model()
    data = model.createData()
    frames = [model.getFrameId(body) for body in g1.FOOT_BODIES]
    q = np.zeros(model.nq)
    q[6] = 1.0
    out = np.zeros(len(postures))
    for i, posture in enumerate(postures):
        q[7:] = posture
        pin.framesForwardKinematics(model, data, q)
        out[i] = -min(data.oMf[f].act(SOLE_OFFSET_M)[2] for f in frames)
    return out
