"""MuJoCo backend: the G1 scene under the robot's own motor law.

The latest MotorCommand is applied through the driver law (g1_control.sim.motor_law) at every
physics step, as the robot's drivers do between host commands. State comes out as the robot
reports it (IMU quaternion/gyro/accelerometer at the pelvis, joint q/dq/tau), plus ground truth
that only a simulator has (base position and velocity), for tests and logs.

Lockstep mode: physics advances only in step(dt) - deterministic and faster than real time.
Wall-clock mode is the same object with `lockstep=False`: the loop paces step() to the wall clock.
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from g1_control.interfaces import Backend
from g1_control.robot import description, g1
from g1_control.scene import SceneConfig
from g1_control.sim.motor_law import motor_torque
from g1_control.types import MotorCommand, RobotState


@dataclass
class MujocoConfig:
    physics_dt_s: float = 0.002
    """Physics step; the motor law is evaluated at this rate (500 Hz by default)."""
    lockstep: bool = True
    motor_temperature_c: float = 40.0
    init_height_clearance_m: float = 0.002
    seed: int = 0


class MujocoBackend(Backend):
    def __init__(self, config: MujocoConfig | None = None, scene: SceneConfig | None = None):
        """scene: tables, platforms and boxes around the robot (g1_control/sim/scene.py). The
        robot's state is read through its own joint addresses, so free boxes in the model do not
        shift it."""
        self.config = config or MujocoConfig()
        self.lockstep = self.config.lockstep
        self.scene = scene or SceneConfig()
        spec = description.mujoco_spec(timestep_s=self.config.physics_dt_s)
        if not self.scene.empty:
            from g1_control.sim.scene import build_scene

            build_scene(spec, self.scene)
        self.model = spec.compile()
        self.data = mujoco.MjData(self.model)
        m = self.model
        base = m.joint(0)  # the robot's floating base is the model's first joint
        qa, va = int(m.jnt_qposadr[base.id]), int(m.jnt_dofadr[base.id])
        self._base_q, self._base_v = slice(qa, qa + 7), slice(va, va + 6)
        # The robot's joints follow its base in the model (objects are added after the robot).
        self._q = slice(qa + 7, qa + 7 + g1.NUM_JOINTS)
        self._v = slice(va + 6, va + 6 + g1.NUM_JOINTS)
        self._command = MotorCommand.damping(g1.KD_DEFAULT)
        self._tau = np.zeros(g1.NUM_JOINTS)
        self._tick = 0
        adr = self.model.sensor_adr
        self._gyro = slice(adr[self.model.sensor("imu_gyro").id], adr[self.model.sensor("imu_gyro").id] + 3)
        self._acc = slice(adr[self.model.sensor("imu_acc").id], adr[self.model.sensor("imu_acc").id] + 3)
        self._quat = slice(adr[self.model.sensor("imu_quat").id], adr[self.model.sensor("imu_quat").id] + 4)
        self._push_force_w = np.zeros(3)
        self._push_until_s = -1.0
        self._push_body = self.model.body(g1.BASE_BODY).id
        # Fall evidence: which geoms are the ground (the world body's: floor, fixed scenery) and
        # which belong to robot bodies other than the feet.
        m = self.model
        feet = {m.body(name).id for name in g1.FOOT_BODIES}
        self._ground_geoms = frozenset(int(g) for g in np.nonzero(m.geom_bodyid == 0)[0])
        self._watched_geoms = frozenset(int(g) for g in range(m.ngeom) if m.body_rootid[m.geom_bodyid[g]] ==
                                        self._push_body and m.geom_bodyid[g] not in feet)
        self.closed = False

    # -- Backend ---------------------------------------------------------------------------------
    def reset(self, q_rad: np.ndarray | None = None, base_pos_xy_m=(0.0, 0.0), yaw_rad: float = 0.0) -> RobotState:
        """Stand the robot at `q_rad` (default pose) with its lowest foot point on the floor."""
        mujoco.mj_resetData(self.model, self.data)
        q = g1.DEFAULT_Q_RAD if q_rad is None else np.asarray(q_rad, dtype=float)
        base = self.data.qpos[self._base_q]
        self.data.qpos[self._q] = q
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
        self._command = MotorCommand(q_rad=q.copy(), kp=g1.KP_DEFAULT.copy(), kd=g1.KD_DEFAULT.copy())
        self._tick = 0
        self._push_until_s = -1.0
        mujoco.mj_forward(self.model, self.data)
        return self.read_state()

    def read_state(self) -> RobotState:
        d = self.data
        return RobotState(
            t_s=float(d.time),
            q_rad=d.qpos[self._q].copy(),
            dq_radps=d.qvel[self._v].copy(),
            tau_nm=self._tau.copy(),
            imu_quat_wxyz=d.sensordata[self._quat].copy(),
            imu_gyro_radps=d.sensordata[self._gyro].copy(),
            imu_acc_mps2=d.sensordata[self._acc].copy(),
            motor_temperature_c=np.full(g1.NUM_JOINTS, self.config.motor_temperature_c),
            mode_machine=g1.G1_29DOF.mode_machine,
            tick=self._tick,
            base_pos_w_m=d.qpos[self._base_q][0:3].copy(),
            base_linvel_w_mps=d.qvel[self._base_v][0:3].copy(),
        )

    def write_command(self, command: MotorCommand) -> None:
        self._command = command

    def step(self, dt_s: float) -> None:
        n = max(1, round(dt_s / self.model.opt.timestep))
        d = self.data
        for _ in range(n):
            motor_torque(self._command, d.qpos[self._q], d.qvel[self._v], out=self._tau)
            d.ctrl[:] = self._tau
            if d.time < self._push_until_s:
                d.xfrc_applied[self._push_body, :3] = self._push_force_w
            else:
                d.xfrc_applied[self._push_body, :3] = 0.0
            mujoco.mj_step(self.model, d)
        self._tick += n

    def close(self) -> None:
        # A simulated robot left alone is damped, like the real one after close().
        self._command = MotorCommand.damping(g1.KD_DEFAULT)
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

    # -- simulation only ----------------------------------------------------------------------------
    def push(self, force_w_n, duration_s: float) -> None:
        """Apply a force (N, world frame) to the pelvis for `duration_s` from now."""
        self._push_force_w = np.asarray(force_w_n, dtype=float)
        self._push_until_s = self.data.time + duration_s

    def object_pose(self, name: str) -> tuple[np.ndarray, np.ndarray]:
        """(position, quaternion wxyz) of a scene box, from the simulator's state."""
        from g1_control.sim.scene import free_body_pose

        return free_body_pose(self.model, self.data, name)

    @property
    def time_s(self) -> float:
        return float(self.data.time)
