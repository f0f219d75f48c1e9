"""MuJoCo backend: the G1 scene under the robot's own motor law.

The latest MotorCommand is applied through the driver law (g1_control.sim.motor_law) at every
physics step, as the robot's drivers do between host commands. MuJoCo evaluates the law itself:
each joint's actuator is a general actuator with an affine bias,

    force = b0 + b1 * q + b2 * dq,   b0 = tau_ff + kp * q* + kd * dq*,  b1 = -kp,  b2 = -kd,

clamped to the joint's effort limit (forcerange), so a physics step is one mj_step and writing a
command only rewrites the bias parameters. A disabled motor gets zero parameters (no torque).
The integrator is semi-implicit Euler: implicitfast would integrate the actuators' kd term
implicitly, which the drivers (and motor_law.py, evaluated once per physics step) do not; the
scene has no joint damping, so Euler is what implicitfast computed when the law ran in Python.
tests/sim/test_mujoco_motor_law.py holds both to motor_law.py. State comes out as the robot
reports it (IMU quaternion/gyro/accelerometer at the pelvis, joint q/dq/tau), plus ground truth
that only a simulator has (base position and velocity), for tests and logs.

Dex3 hands (MujocoConfig.hands 'dex3'): each finger joint has a motor after the body's 29 under
the hand's own motor law (HandCmd_'s q, dq, kp, kd, tau), written with write_fingers and read with
read_fingers (the torque is what the motor applied), applied at once (no latency draw); the loop
drives them through the hands' safety layer (sim/mujoco_hands.py, trackers/hands.py).

Friction is Coulomb's in every scene, the bare floor included (SceneConfig.grip_physics: elliptic
cones, impratio 100; MuJoCo's defaults let stance feet slide inside the friction they were given).

Randomised robot (MujocoConfig.randomize, g1_control/sim/randomize.py): the compiled model's link
masses, CoMs, foot friction and torque limits are the draw's; each driver law is scaled by its
motor's drawn strength and reaches the drivers the drawn latency (in whole physics steps) after
write_command, so a lockstep batch of ticks switches law inside the batch. reset() and close()
apply their command at once and drop any still on its way.

Lockstep mode: physics advances only in step(dt) - deterministic and faster than real time.
Wall-clock mode is the same object with `lockstep=False`: the loop paces step() to the wall clock.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass

import mujoco
import numpy as np

from g1_control.errors import RobotDescriptionError
from g1_control.interfaces import Backend
from g1_control.robot import description, dex3, g1
from g1_control.scene import SceneConfig
from g1_control.sim.randomize import RandomizeConfig, RobotDraw, draw
from g1_control.types import FingerCommand, FingerState, MotorCommand, RobotState


def motor_law_scene(physics_dt_s: float, variant: g1.Variant = g1.G1_29DOF, hands: str = "none",
                    hard_stops: bool = False) -> mujoco.MjSpec:
    """The G1 scene (robot/description.py) of `variant` (with `hands`) with the drivers' motor law
    in its actuators (see above): one actuator per joint the variant has."""
    spec = description.mujoco_spec(timestep_s=physics_dt_s, variant=variant, hands=hands, hard_stops=hard_stops)
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_EULER
    for i in variant.active_joints:
        name = g1.JOINT_NAMES[i]
        actuator = spec.actuator(name.removesuffix("_joint"))
        actuator.gaintype = mujoco.mjtGain.mjGAIN_FIXED
        actuator.gainprm[0] = 0.0  # ctrl unused: the whole law sits in the bias
        actuator.biastype = mujoco.mjtBias.mjBIAS_AFFINE
        actuator.ctrllimited = mujoco.mjtLimited.mjLIMITED_FALSE
        actuator.forcelimited = mujoco.mjtLimited.mjLIMITED_TRUE
        limit = float(g1.EFFORT_LIMIT_NM[i])
        actuator.forcerange = [-limit, limit]
    return spec


@dataclass
class MujocoConfig:
    physics_dt_s: float = 0.002
    """Physics step; the motor law is evaluated at this rate (500 Hz by default)."""
    lockstep: bool = True
    motor_temperature_c: float = 40.0
    init_height_clearance_m: float = 0.002
    seed: int = 0
    hands: str = "none"
    """'dex3': the G1 with Dex3-1 hands (a motor per finger, holding the open pose until
    write_fingers commands it; robot/description.py; 29-DoF G1 only)."""
    variant: str = "g1_29dof"
    """Which G1 is built (g1.VARIANTS by name; a launch file's backend.expected_variant): a variant
    without some joints has no such joints and motors in the model, and its state reports them as 0
    (q, dq, tau), as the robot's LowState_ does for the slots it has no motor behind."""
    hard_joint_stops: bool = False
    """The joints' stops hard (robot/description.py JOINT_STOP_*), as the emulated robot has them
    (`g1 sim-robot`); False: MuJoCo's default soft limits (a joint striking one goes 0.02-0.05 rad past)."""
    randomize: RandomizeConfig | None = None
    """A seeded domain randomisation of the robot (g1_control/sim/randomize.py): link masses, CoM
    offsets, motor strength, command latency, foot friction. None: the nominal robot."""


class MujocoBackend(Backend):
    def __init__(self, config: MujocoConfig | None = None, scene: SceneConfig | None = None):
        """scene: tables, platforms and boxes around the robot (g1_control/sim/scene.py). The
        robot's state is read through its own joint addresses, so free boxes in the model do not
        shift it."""
        self.config = config or MujocoConfig()
        self.lockstep = self.config.lockstep
        self.scene = scene or SceneConfig()
        try:
            self.variant = g1.variant_named(self.config.variant)
        except ValueError as exc:
            raise RobotDescriptionError(f"MujocoConfig.variant: {exc}") from None
        self.model = self._compile()
        self.data = mujoco.MjData(self.model)
        self.draw: RobotDraw | None = None
        """The randomisation this robot runs with (None: nominal)."""
        self._strength: np.ndarray | None = None
        """Per model actuator: the drawn motor strength (None: 1)."""
        self._latency_steps = 0
        self._pending: deque[tuple[int, np.ndarray]] = deque()
        """Driver laws written but not yet applied: (physics step they apply at, bias parameters)."""
        self._steps = 0
        m = self.model
        base = m.joint(0)  # the robot's floating base is the model's first joint
        qa, va = int(m.jnt_qposadr[base.id]), int(m.jnt_dofadr[base.id])
        self._base_q, self._base_v = slice(qa, qa + 7), slice(va, va + 6)
        # The robot's joints follow its base in the model (objects are added after the robot); with
        # Dex3 hands, each hand's finger joints sit between its arm and the next limb.
        n = self.variant.num_dof
        self._active = np.array(self.variant.active_joints)
        """The robot's joint indices (g1.JOINT_NAMES) of the model's joints and actuators, in order."""
        names = [g1.JOINT_NAMES[i] for i in self._active]
        qadr = np.array([m.jnt_qposadr[m.joint(name).id] for name in names])
        vadr = np.array([m.jnt_dofadr[m.joint(name).id] for name in names])
        self._contiguous = bool(np.array_equal(qadr, np.arange(qa + 7, qa + 7 + n))
                                and np.array_equal(vadr, np.arange(va + 6, va + 6 + n)))
        self._q: slice | np.ndarray = slice(qa + 7, qa + 7 + n) if self._contiguous else qadr
        self._v: slice | np.ndarray = slice(va + 6, va + 6 + n) if self._contiguous else vadr
        self._full = n == g1.NUM_JOINTS
        self._bias = self.model.actuator_biasprm[:n, :3]
        """(b0, b1, b2) per motor: a view into the model, rewritten by write_command."""
        self._law = np.zeros((3, g1.NUM_JOINTS))
        if self.config.randomize is not None:
            self._randomize(self.config.randomize)
        self._command = MotorCommand.damping(g1.KD_DEFAULT)
        self._apply_now(self._command)
        self._tick = 0
        adr = self.model.sensor_adr
        self._gyro = slice(adr[self.model.sensor("imu_gyro").id], adr[self.model.sensor("imu_gyro").id] + 3)
        self._acc = slice(adr[self.model.sensor("imu_acc").id], adr[self.model.sensor("imu_acc").id] + 3)
        self._quat = slice(adr[self.model.sensor("imu_quat").id], adr[self.model.sensor("imu_quat").id] + 4)
        # What read_state reports, as views into MjData's arrays (MuJoCo keeps them in place).
        d = self.data
        self._views = (d.qpos[self._q], d.qvel[self._v], d.actuator_force[:n], d.sensordata[self._quat],
                       d.sensordata[self._gyro], d.sensordata[self._acc], d.qpos[qa:qa + 3], d.qvel[va:va + 3])
        self._temperature = np.full(g1.NUM_JOINTS, float(self.config.motor_temperature_c))
        # Dex3 fingers (hands 'dex3'): one motor per finger joint after the body's (robot/description.py)
        self._fingers: dict[str, tuple[np.ndarray, np.ndarray, np.ndarray]] = {}
        self._finger_enabled: dict[str, np.ndarray] = {}
        if self.config.hands == "dex3":
            for side in dex3.SIDES:
                fingers = dex3.joint_names(side)
                self._fingers[side] = (np.array([m.actuator(n.removesuffix("_joint")).id for n in fingers]),
                                       np.array([m.jnt_qposadr[m.joint(n).id] for n in fingers]),
                                       np.array([m.jnt_dofadr[m.joint(n).id] for n in fingers]))
                self._finger_enabled[side] = np.ones(dex3.NUM_MOTORS, dtype=bool)
        self._finger_hold = {side: m.actuator_biasprm[acts, :3].copy() for side, (acts, _, _) in self._fingers.items()}
        """Each hand's motor law as compiled (the open pose held), for reset()."""
        self._push_force_w = np.zeros(3)
        self._push_until_s = -1.0
        self._pushing = False
        self._push_body = self.model.body(g1.BASE_BODY).id
        # Fall evidence: which geoms are the ground (the world body's: floor, fixed scenery) and
        # which belong to robot bodies other than the feet.
        m = self.model
        feet = {m.body(name).id for name in g1.FOOT_BODIES}
        self._ground_geoms = frozenset(int(g) for g in np.nonzero(m.geom_bodyid == 0)[0])
        self._watched_geoms = frozenset(int(g) for g in range(m.ngeom) if m.body_rootid[m.geom_bodyid[g]] ==
                                        self._push_body and m.geom_bodyid[g] not in feet)
        self.closed = False

    def _compile(self) -> mujoco.MjModel:
        spec = motor_law_scene(self.config.physics_dt_s, self.variant, self.config.hands, self.config.hard_joint_stops)
        from g1_control.sim.scene import build_scene

        build_scene(spec, self.scene)  # an empty scene too: its floor's friction (scene.py grip_physics)
        return spec.compile()

    # -- Backend ---------------------------------------------------------------------------------
    def reset(self, q_rad: np.ndarray | None = None, base_pos_xy_m=(0.0, 0.0), yaw_rad: float = 0.0) -> RobotState:
        """Stand the robot at `q_rad` (default pose) with its lowest foot point on the floor."""
        mujoco.mj_resetData(self.model, self.data)
        q = g1.DEFAULT_Q_RAD if q_rad is None else np.asarray(q_rad, dtype=float)
        base = self.data.qpos[self._base_q]
        self.data.qpos[self._q] = q[self._active]
        base[3:7] = [np.cos(yaw_rad / 2), 0.0, 0.0, np.sin(yaw_rad / 2)]
        base[0:2] = base_pos_xy_m
        base[2] = 1.0
        mujoco.mj_kinematics(self.model, self.data)
        m, robot = self.model, self.model.body(g1.BASE_BODY).id
        lowest = min(
            self.data.geom_xpos[i][2] - (m.geom_size[i][0] if m.geom_type[i] == mujoco.mjtGeom.mjGEOM_SPHERE else 0.0)
            for i in range(m.ngeom)
            if m.geom_conaffinity[i] and m.geom_bodyid[i] != 0 and m.body_rootid[m.geom_bodyid[i]] == robot
        )
        base[2] += -lowest + self.config.init_height_clearance_m
        self._apply_now(MotorCommand(q_rad=q.copy(), kp=g1.KP_DEFAULT.copy(), kd=g1.KD_DEFAULT.copy()))
        for side, (acts, _, _) in self._fingers.items():  # the hands hold the open pose again
            self.model.actuator_biasprm[acts, :3] = self._finger_hold[side]
            self._finger_enabled[side][:] = True
        self._tick = 0
        self._push_until_s = -1.0
        self._pushing = False
        mujoco.mj_forward(self.model, self.data)
        return self.read_state()

    def read_state(self) -> RobotState:
        q, dq, tau, quat, gyro, acc, pos, vel = self._views
        if not self._contiguous:  # gathered (fancy indexing made copies, not views, in __init__)
            q, dq = self.data.qpos[self._q], self.data.qvel[self._v]
        if not self._full:  # the slots of joints the variant lacks read 0, as on the robot
            q, dq, tau = (self._scatter(x) for x in (q, dq, tau))
        return RobotState(
            t_s=float(self.data.time),
            q_rad=q.copy(),
            dq_radps=dq.copy(),
            tau_nm=tau.copy(),
            imu_quat_wxyz=quat.copy(),
            imu_gyro_radps=gyro.copy(),
            imu_acc_mps2=acc.copy(),
            motor_temperature_c=self._temperature.copy(),
            mode_machine=self.variant.mode_machine,
            tick=self._tick,
            base_pos_w_m=pos.copy(),
            base_linvel_w_mps=vel.copy(),
        )

    def write_command(self, command: MotorCommand) -> None:
        """Hand `command` to the simulated drivers (taken by value, as the robot's link encodes it)."""
        self._command = command
        law = self._law
        np.multiply(command.kp, command.q_rad, out=law[0])
        law[0] += command.kd * command.dq_radps
        law[0] += command.tau_nm
        np.negative(command.kp, out=law[1])
        np.negative(command.kd, out=law[2])
        if not command.enable.all():
            law[:, ~command.enable] = 0.0
        bias = law.T if self._full else law[:, self._active].T
        if self._strength is not None:
            bias = bias * self._strength[:, None]
        if self._latency_steps:  # the drivers get it this many physics steps from now
            self._pending.append((self._steps + self._latency_steps, np.array(bias)))
        else:
            self._bias[:] = bias

    def _apply_now(self, command: MotorCommand) -> None:
        """`command` at the drivers at once, and any command still on its way dropped (reset, close)."""
        self._pending.clear()
        self.write_command(command)
        if self._pending:
            self._bias[:] = self._pending.pop()[1]

    def _randomize(self, config: RandomizeConfig) -> None:
        """Apply the draw of `config` to the compiled model (sim/randomize.py)."""
        m = self.model
        robot = m.body(g1.BASE_BODY).id
        ids = [b for b in range(1, m.nbody) if m.body_rootid[b] == robot]
        d = draw(config, tuple(m.body(b).name for b in ids), g1.NUM_JOINTS)
        m.body_mass[ids] *= d.mass_scale
        m.body_inertia[ids] *= d.mass_scale[:, None]
        m.body_ipos[ids] += d.com_offset_m
        self._strength = d.motor_strength[self._active].copy()
        m.actuator_forcerange[: len(self._strength)] *= self._strength[:, None]
        feet = {m.body(name).id for name in g1.FOOT_BODIES}
        for geom in range(m.ngeom):
            if m.geom_bodyid[geom] in feet and m.geom_conaffinity[geom]:
                m.geom_friction[geom, 0] = d.foot_friction
                m.geom_priority[geom] = 1  # the feet's friction, not the larger of the two geoms'
        self._latency_steps = max(0, round(d.latency_s / m.opt.timestep))
        mujoco.mj_setConst(m, self.data)
        self.draw = d

    @property
    def latency_s(self) -> float:
        """The command latency this robot applies (the drawn value rounded to physics steps)."""
        return self._latency_steps * float(self.model.opt.timestep)

    def describe(self) -> str:
        if self.draw is None:
            return type(self).__name__
        return (f"{type(self).__name__} randomised ({self.draw.summary()}; latency applied "
                f"{1000 * self.latency_s:.0f} ms = {self._latency_steps} physics steps)")

    def _scatter(self, values: np.ndarray) -> np.ndarray:
        """The variant's joint values in the robot's 29 slots (0 where it has no joint)."""
        out = np.zeros(g1.NUM_JOINTS)
        out[self._active] = values
        return out

    def step(self, dt_s: float) -> None:
        self._physics_steps(max(1, round(dt_s / self.model.opt.timestep)))

    def step_ticks(self, command: MotorCommand, dt_s: float, n: int) -> None:
        # Writing the same command again changes nothing here: n ticks are one run of physics steps.
        # The command last written is not written again: the loop hands on the command it wrote
        # on the tick before, unchanged (see Backend.step_ticks).
        if command is not self._command:
            self.write_command(command)
        self._physics_steps(n * max(1, round(dt_s / self.model.opt.timestep)))

    def _physics_steps(self, n: int) -> None:
        m, d = self.model, self.data
        self._tick += n
        pending = self._pending
        while n > 0:
            while pending and pending[0][0] <= self._steps:  # commands that reach the drivers now
                self._bias[:] = pending.popleft()[1]
            k = n if not pending else min(n, pending[0][0] - self._steps)
            if d.time < self._push_until_s:  # a push acts on every physics step that starts before it ends
                d.xfrc_applied[self._push_body, :3] = self._push_force_w
                k = 1
            elif self._pushing:
                d.xfrc_applied[self._push_body, :3] = 0.0
                self._pushing = False
            mujoco.mj_step(m, d, k)
            self._steps += k
            n -= k

    def close(self) -> None:
        # A simulated robot left alone is damped, like the real one after close().
        self._apply_now(MotorCommand.damping(g1.KD_DEFAULT))
        self.closed = True

    def ground_contacts(self) -> tuple[str, ...]:
        d = self.data
        if d.ncon == 0:
            return ()
        ground, watched = self._ground_geoms, self._watched_geoms
        bodies = set()
        for a, b in d.contact.geom.tolist():  # a handful of contacts: plain Python is cheapest
            if a in ground and b in watched:
                bodies.add(int(self.model.geom_bodyid[b]))
            elif b in ground and a in watched:
                bodies.add(int(self.model.geom_bodyid[a]))
        return tuple(sorted(self.model.body(i).name for i in bodies)) if bodies else ()

    # -- Dex3 hands (hands 'dex3') ------------------------------------------------------------------
    @property
    def hand_sides(self) -> tuple[str, ...]:
        """The hands this robot has fingers on (('left', 'right') with Dex3 hands, else ())."""
        return tuple(self._fingers)

    def _hand(self, side: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        dex3.check_side(side)
        if side not in self._fingers:
            raise RobotDescriptionError(f"this simulated G1 has no Dex3 hands (backend.hands is "
                                        f"{self.config.hands!r}); no {side} fingers to command or read")
        return self._fingers[side]

    def write_fingers(self, side: str, command: FingerCommand) -> None:
        """One Dex3 hand's command to its simulated motors, the hand's motor law (HandCmd_'s fields,
        tau = kp (q* - q) + kd (dq* - dq) + tau_ff, each motor force limited to its URDF effort),
        from the next physics step on; a disabled motor gets no torque. A non-finite command is
        refused (ValueError) and the motors keep the last law: vetting and damping are the hands'
        safety layer's (safety/hands.py), as on the robot."""
        acts = self._hand(side)[0]
        if not command.is_finite():
            raise ValueError(f"{side} hand command is not finite; not applied")
        on = command.enable.astype(float)
        b = self.model.actuator_biasprm
        b[acts, 0] = on * (command.kp * command.q_rad + command.kd * command.dq_radps + command.tau_nm)
        b[acts, 1] = -on * command.kp
        b[acts, 2] = -on * command.kd
        self._finger_enabled[side] = command.enable.copy()

    def read_fingers(self, side: str) -> FingerState:
        """One hand's state as HandState_ reports it: finger angles, speeds, the motors' torque (the
        force MuJoCo applied, within the effort limit), stamped with the simulated time."""
        acts, qadr, vadr = self._hand(side)
        d = self.data
        return FingerState(q_rad=d.qpos[qadr].copy(), dq_radps=d.qvel[vadr].copy(),
                           tau_nm=d.actuator_force[acts].copy(),
                           temperature_c=np.full(dex3.NUM_MOTORS, float(self.config.motor_temperature_c)),
                           motor_enabled=self._finger_enabled[side].copy(), t_s=float(d.time))

    # -- simulation only ----------------------------------------------------------------------------
    def push(self, force_w_n, duration_s: float) -> None:
        """Apply a force (N, world frame) to the pelvis for `duration_s` from now."""
        self._push_force_w = np.asarray(force_w_n, dtype=float)
        self._push_until_s = self.data.time + duration_s
        self._pushing = True

    def object_pose(self, name: str) -> tuple[np.ndarray, np.ndarray]:
        """(position, quaternion wxyz) of a scene box, from the simulator's state."""
        from g1_control.sim.scene import free_body_pose

        return free_body_pose(self.model, self.data, name)

    @property
    def time_s(self) -> float:
        return float(self.data.time)
