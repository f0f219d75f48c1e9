"""The robot emulator behind `g1 sim-robot`: a physics backend (MuJoCo, or MockG1) speaking the
G1's DDS protocol, so the unchanged robot path can run against simulation (sim2sim).

It behaves like the robot where the host can tell: LowState_ at 500 Hz with CRC and tick; LowCmd_
with a bad CRC or a foreign mode_machine dropped; motor enable honoured; a motion service whose
built-in controller holds the robot standing and ignores rt/lowcmd until it is released, after
which the motors damp until the host's first command. Faults can be injected by name (for the
fault-injection suite), from code or, in `--control-stdin` mode, one per input line.

Loopback only: the emulator refuses any interface but `lo` (no robot traffic off this host).
"""

from __future__ import annotations

import json
import math
import sys
import threading
import time
from typing import TYPE_CHECKING

import numpy as np

from g1_control.errors import NetworkInterfaceError
from g1_control.hardware.links.dds import DdsLink
from g1_control.hardware.links.network import LOOPBACK
from g1_control.hardware.unitree.motion_service import MotionServiceEmulator
from g1_control.hardware.unitree.remote import encode_wireless_remote
from g1_control.interfaces import Backend
from g1_control.robot import g1
from g1_control.rotations import yaw_of
from g1_control.sim.robot_endpoint import RobotEndpoint
from g1_control.types import MotorCommand, RobotState

if TYPE_CHECKING:
    from g1_control.hardware.ros2.topics import ObjectPosesWriter, PlatformPosesWriter, PoseTopicWriter
    from g1_control.sim.ground_truth import GroundTruthRecorder
    from g1_control.sim.mocap import MocapConfig, SimulatedMocap, SimulatedPerception
    from g1_control.sim.mujoco_backend import MujocoBackend

CRC_BURST_STATES = 10
"""States with a wrong CRC in one "crc_burst": 20 ms at 500 Hz, under the host's 50 ms stale-state limit."""
COLLAPSED_LEG_Q_RAD = np.array([-1.6, 0.0, 0.0, 2.6, -0.8, 0.0])
"""One leg (hip pitch, roll, yaw, knee, ankle pitch, roll) of a collapsed G1: inside the joint limits."""

FAULTS = {
    "state_stops": "LowState_ stops (robot side silent)",
    "state_frozen": "LowState_ keeps arriving with the same contents and tick",
    "crc_corrupted": "every LowState_ carries a wrong CRC",
    "crc_burst": f"the next {CRC_BURST_STATES} LowState_ carry a wrong CRC, then the stream is clean again "
                 "(a burst too short to make the state stale)",
    "tilt": "pelvis tilted 1.3 rad (fall)",
    "collapse": "the legs report a deep squat (pelvis ~0.31 m above the soles by leg kinematics) with the IMU "
                "upright: a robot sinking to the floor, which only the estimator's pelvis height shows",
    "overspeed": "left knee reports 30 rad/s",
    "over_temperature": "waist yaw motor reports 110 degC",
    "clear": "remove every injected fault",
}
REMOTE_COMMANDS = {
    "press B1[+B2...]": "press remote buttons for 0.15 s (e.g. press start, press A, press L1+R1)",
    "hold B1[+B2...]": "hold remote buttons down ('hold' alone releases them)",
    "stick NAME VALUE": "set a remote stick: lx, ly (forward +), rx, ry, l2 in [-1, 1]",
}
REMOTE_PRESS_S = 0.15
EMULATOR_MODES = ("robot", "unitree_mujoco")
"""What the emulator plays: the G1 itself, or Unitree's MuJoCo simulator (g1_control/sim/unitree_mujoco.py)."""


class FaultyPhysics(Backend):
    """Wraps the physics to corrupt what the robot reports (sensor-side faults)."""

    def __init__(self, inner: Backend):
        self.inner = inner
        self.lockstep = inner.lockstep
        self.tilt_rad = 0.0
        self.overspeed_joint: int | None = None
        self.hot_joint: int | None = None
        self.collapsed = False
        # The operator's Unitree remote, as the robot reports it inside LowState_ (press/stick).
        self.remote_held: frozenset[str] = frozenset()
        self.remote_pressed: frozenset[str] = frozenset()
        self.remote_pressed_until = 0.0
        self.remote_sticks = {"lx": 0.0, "rx": 0.0, "ry": 0.0, "l2": 0.0, "ly": 0.0}

    def reset(self) -> RobotState:
        return self.inner.reset()

    def read_state(self) -> RobotState:
        state = self.inner.read_state()
        held = self.remote_held | (self.remote_pressed if time.monotonic() < self.remote_pressed_until else frozenset())
        state.wireless_remote = encode_wireless_remote(held, **self.remote_sticks)
        if self.tilt_rad:
            half = self.tilt_rad / 2
            state.imu_quat_wxyz = np.array([np.cos(half), np.sin(half), 0.0, 0.0])
        if self.collapsed:
            state.q_rad[0:6] = state.q_rad[6:12] = COLLAPSED_LEG_Q_RAD  # left leg, right leg
        if self.overspeed_joint is not None:
            state.dq_radps[self.overspeed_joint] = 30.0
        if self.hot_joint is not None:
            state.motor_temperature_c[self.hot_joint] = 110.0
        return state

    def write_command(self, command: MotorCommand) -> None:
        self.inner.write_command(command)

    def step(self, dt_s: float) -> None:
        self.inner.step(dt_s)

    def close(self) -> None:
        self.inner.close()


class Gantry(Backend):
    """A gantry for the MuJoCo G1, like the frame a real G1 hangs from on its first runs (and
    unitree_mujoco's elastic band): spring-dampers on the pelvis position (pulling up, never
    pushing) and on its roll/pitch, anchored at the reset pose, so a robot whose controller is
    still being tried does not fall. Yaw stays free. Needs MujocoBackend (its push() for the force,
    its MjData for the torque, which push() leaves alone)."""

    def __init__(self, inner: Backend, stiffness_npm: float = 3000.0, damping_nspm: float = 400.0,
                 rot_stiffness_nmprad: float = 800.0, rot_damping_nmsprad: float = 80.0,
                 mass_kg: float = 35.0, physics_dt_s: float = 0.002, lower_on_policy: bool = False,
                 held_before_policy_s: float = 0.3):
        """lower_on_policy: take the gantry away when the policy takes over, as the operator lowers
        the robot onto its feet: when stiff leg targets that were held still for at least
        `held_before_policy_s` (the deploy's hold) start to move (the policy's first actions). A
        plain PD hold on the floor falls (docs/robot_facts.md), so the gantry must carry the robot until then."""
        from g1_control.sim.mujoco_backend import MujocoBackend

        if not isinstance(inner, MujocoBackend):
            raise TypeError(f"{type(inner).__name__} cannot take external forces; the gantry needs MujocoBackend")
        self.inner, self.lockstep = inner, inner.lockstep
        self.k, self.c, self.k_rot, self.c_rot = stiffness_npm, damping_nspm, rot_stiffness_nmprad, rot_damping_nmsprad
        self.weight_n = mass_kg * 9.81
        self.dt = physics_dt_s
        self.anchor = np.zeros(3)
        self._pelvis = inner.model.body(g1.BASE_BODY).id
        self.lower_on_policy = lower_on_policy
        self.held_before_policy_s = held_before_policy_s
        self.lowered = False
        self.lowered_at_s = float("nan")
        """time.monotonic() when the gantry was lowered."""
        self.lowered_base_pos_m: np.ndarray | None = None
        self._held_q: np.ndarray | None = None
        self._held_since_s = 0.0
        # the pelvis' rotational unit vectors in joint space, and M^-1 of them (reused every step)
        self._unit = np.zeros((3, inner.model.nv))
        self._unit[0, 3] = self._unit[1, 4] = self._unit[2, 5] = 1.0
        self._solved = np.zeros_like(self._unit)

    def reset(self) -> RobotState:
        state = self.inner.reset()
        assert state.base_pos_w_m is not None  # MuJoCo states carry the ground-truth base pose
        self.anchor = state.base_pos_w_m.copy()
        return state

    def read_state(self) -> RobotState:
        return self.inner.read_state()

    def write_command(self, command: MotorCommand) -> None:
        if self.lower_on_policy and not self.lowered:
            self._watch_for_policy(command)
        self.inner.write_command(command)

    def _watch_for_policy(self, command: MotorCommand) -> None:
        legs = list(g1.LEG_JOINTS)
        now = time.monotonic()
        stiff = bool(np.all(command.enable[legs]) and np.all(command.kp[legs] > 0))
        q = command.q_rad[legs]
        if not stiff:
            self._held_q = None
            return
        if self._held_q is None or np.max(np.abs(q - self._held_q)) > 1e-4:
            if self._held_q is not None and now - self._held_since_s >= self.held_before_policy_s:
                self.lowered, self.lowered_at_s = True, now
                self.lowered_base_pos_m = self.inner.data.qpos[0:3].copy()
                self.inner.data.xfrc_applied[self._pelvis, 3:] = 0.0
            self._held_q, self._held_since_s = q.copy(), now

    def step(self, dt_s: float) -> None:
        if self.lowered:
            self.inner.step(dt_s)
            return
        d = self.inner.data
        for _ in range(max(1, round(dt_s / self.dt))):
            force = self.k * (self.anchor - d.qpos[0:3]) - self.c * d.qvel[0:3]
            force[2] = max(0.0, force[2] + self.weight_n * 0.9)  # a band pulls, never pushes
            self.inner.push(force, self.dt)
            # Roll/pitch spring: the body z axis is pulled back to world up (torque ~ z_body x up).
            rot = d.xmat[self._pelvis].reshape(3, 3)
            z_body = rot[:, 2]
            omega_w = rot @ d.qvel[3:6]  # free-joint angular velocity is in the body frame
            torque = self.k_rot * np.cross(z_body, [0.0, 0.0, 1.0]) + self._damping_torque(rot, omega_w)
            d.xfrc_applied[self._pelvis, 3:] = torque
            self.inner.step(self.dt)

    def _damping_torque(self, rot: np.ndarray, omega_w: np.ndarray) -> np.ndarray:
        """The roll/pitch damper, integrated implicitly: tau = -C (omega + dt A tau), A = the pelvis'
        angular mobility in the world frame (the free joint's block of M^-1, joints free). Explicitly
        (tau = -C omega) it is unstable whenever c dt exceeds twice the pelvis' effective inertia: the
        limp pelvis alone has ~0.009 kg m^2, so c = 80 N m s/rad at 2 ms made the emulated robot's
        pelvis and waist flip +-40 rad/s every step while its motors damped, and the host's
        over-speed check tripped."""
        import mujoco

        mujoco.mj_solveM(self.inner.model, self.inner.data, self._solved, self._unit)  # last step's factor
        mobility_w = rot @ self._solved[:, 3:6] @ rot.T
        c = np.diag([self.c_rot, self.c_rot, 0.0])
        return -np.linalg.solve(np.eye(3) + self.dt * c @ mobility_w, c @ omega_w)

    def close(self) -> None:
        self.inner.data.xfrc_applied[self._pelvis, 3:] = 0.0
        self.inner.close()


class RobotEmulator:
    def __init__(self, physics: Backend, interface: str = LOOPBACK, domain_id: int = 1,
                 partition: str | None = None, rate_hz: float = 500.0, builtin_mode: str = "ai",
                 mode: str = "robot"):
        """mode: robot (the G1's protocol), or unitree_mujoco (that simulator's traits: LowState_ with
        crc/tick/mode_machine 0 at 200 Hz, no motion service; its held-torque motor law is the physics'
        own: g1_control/sim/unitree_mujoco.py)."""
        if mode not in EMULATOR_MODES:
            raise ValueError(f"emulator mode '{mode}' is not one of {', '.join(EMULATOR_MODES)}")
        if interface != LOOPBACK:
            raise NetworkInterfaceError(
                f"the robot emulator runs on loopback only (interface '{LOOPBACK}'); got '{interface}'. "
                "Point the host at the emulator with the same interface and domain")
        self.physics = FaultyPhysics(physics)
        self.state0 = self.physics.reset()
        self.mode = mode
        if mode == "unitree_mujoco":
            rate_hz, builtin_mode = self._unitree_mujoco_traits()
        self.link = DdsLink("robot", interface, domain_id, partition=partition)
        self.endpoint = RobotEndpoint(self.link, self.physics, rate_hz=rate_hz)
        self.endpoint.unset_state_fields = mode == "unitree_mujoco"
        # Until released, the built-in controller "holds" the robot: physics paused at the standing
        # pose, host commands ignored. Released with no host command yet, the motors damp, as in
        # the remote's debug mode.
        self.endpoint.builtin_active = bool(builtin_mode)
        if not builtin_mode:
            self.physics.write_command(MotorCommand.damping(g1.KD_DEFAULT))
        self.service = MotionServiceEmulator(self.link._participant, partition, active_mode=builtin_mode,
                                             on_change=self._on_mode_change) if mode == "robot" else None
        self._lock = threading.Lock()
        self.mocap: SimulatedMocap | None = None
        self._mocap_writer: PoseTopicWriter | None = None
        self.perception: SimulatedPerception | None = None
        self.scene_sim: MujocoBackend | None = None
        """The MuJoCo physics holding a launch file's scene (publish_perception), for its ground truth."""
        self._perception_writer: ObjectPosesWriter | None = None
        self._platform_writer: PlatformPosesWriter | None = None

    @staticmethod
    def _unitree_mujoco_traits() -> tuple[float, str]:
        """(LowState_ rate, built-in controller) of Unitree's MuJoCo simulator: 200 Hz, none."""
        from g1_control.sim.unitree_mujoco import PROFILE

        return PROFILE.state_rate_hz, ""

    def _on_mode_change(self, mode: str) -> None:
        self.endpoint.builtin_active = bool(mode)
        if not mode and self.endpoint.last_command is None:
            self.physics.write_command(MotorCommand.damping(g1.KD_DEFAULT))

    def remote(self, line: str) -> float:
        """Operate the emulated Unitree remote (see REMOTE_COMMANDS); return the time.monotonic()."""
        from g1_control.hardware.unitree.remote import REMOTE_BUTTON_BITS

        words = line.split()
        p = self.physics
        if words[0] in ("press", "hold"):
            buttons = frozenset(b for w in words[1:] for b in w.split("+"))
            unknown = buttons - set(REMOTE_BUTTON_BITS)
            if unknown:
                raise ValueError(f"unknown remote buttons {sorted(unknown)}; known: {', '.join(REMOTE_BUTTON_BITS)}")
            if words[0] == "hold":
                p.remote_held = buttons
            else:
                p.remote_pressed, p.remote_pressed_until = buttons, time.monotonic() + REMOTE_PRESS_S
        elif words[0] == "stick" and len(words) == 3 and words[1] in p.remote_sticks:
            value = float(words[2])
            if not -1.0 <= value <= 1.0:
                raise ValueError(f"stick value {value} is outside [-1, 1]")
            p.remote_sticks[words[1]] = value
        else:
            raise ValueError(f"cannot read remote command '{line}'; known: {'; '.join(REMOTE_COMMANDS)}")
        return time.monotonic()

    def inject(self, fault: str) -> float:
        """Apply fault `fault` (see FAULTS); return the time.monotonic() it took effect."""
        if fault not in FAULTS:
            raise ValueError(f"unknown fault '{fault}'; known: {', '.join(FAULTS)}")
        e, p = self.endpoint, self.physics
        if fault == "clear":
            e.mark_faults_clear()
            p.tilt_rad, p.overspeed_joint, p.hot_joint, p.collapsed = 0.0, None, None, False
        elif fault == "state_stops":
            e.publish = False
        elif fault == "state_frozen":
            e.freeze_state = True
        elif fault == "crc_corrupted":
            e.corrupt_state_crc = True
        elif fault == "crc_burst":
            e.corrupt_next_states = CRC_BURST_STATES
        elif fault == "collapse":
            p.collapsed = True
        elif fault == "tilt":
            p.tilt_rad = 1.3
        elif fault == "overspeed":
            p.overspeed_joint = g1.JOINT_INDEX["left_knee_joint"]
        elif fault == "over_temperature":
            p.hot_joint = g1.JOINT_INDEX["waist_yaw_joint"]
        return time.monotonic()

    def publish_mocap(self, config: MocapConfig, topic: str = "mocap/pose",
                      start_in_scene: list[float] | None = None) -> SimulatedMocap:
        """Publish a motion-capture pose of the pelvis from the simulator's ground truth on rt/<topic>
        (geometry_msgs/PoseStamped, frame 'mocap' = the scene frame), stamped with the wall clock when
        measured and sent `latency_s` later (sim/mocap.py). The simulator's world is the robot's start
        frame; `start_in_scene` (x, y, yaw: the launch file's scene.robot_start) maps it into the scene's."""
        from g1_control.hardware.ros2.topics import PoseTopicWriter
        from g1_control.sim.mocap import SimulatedMocap

        mocap = SimulatedMocap(config)
        writer = PoseTopicWriter(self.link.interface, self.link.domain_id, topic, self.link.partition)
        self._mocap_writer = writer

        def sample(state: RobotState) -> None:
            if state.base_pos_w_m is None:
                return
            for stamp, pos, quat in mocap.sample(time.time(), state.base_pos_w_m, state.imu_quat_wxyz):
                if start_in_scene is not None:
                    pos, quat = _start_to_scene(start_in_scene, pos, quat)
                writer.write(stamp, pos, quat)

        self.endpoint.state_observers.append(sample)
        self.mocap = mocap
        return mocap

    def publish_perception(self, sim: MujocoBackend, config: MocapConfig, topic: str = "perception/objects"
                           ) -> SimulatedPerception:
        """Publish the scene's boxes and platforms as a perception system on the robot sees them, from
        `sim`'s ground truth (sim/mocap.py): boxes as ObjectPoses_ on rt/<topic>, platforms (the centre of
        the top face, its yaw, footprint and height) as PlatformPoses_ on rt/<topic>/platforms, each in the
        robot's heading frame. One camera: a frame's noise, latency and dropout are shared by both."""
        from g1_control.hardware.ros2.topics import PLATFORMS_SUFFIX, ObjectPosesWriter, PlatformPosesWriter
        from g1_control.sim.mocap import SimulatedPerception

        boxes = [b.name for b in sim.scene.boxes]
        platforms = {p.name: p for p in sim.scene.platforms}
        if not boxes and not platforms:
            raise ValueError("perception: the scene has no boxes or platforms to publish")
        perception = SimulatedPerception(config)
        if boxes:
            self._perception_writer = ObjectPosesWriter(self.link.interface, self.link.domain_id, topic,
                                                        self.link.partition)
        if platforms:
            self._platform_writer = PlatformPosesWriter(self.link.interface, self.link.domain_id,
                                                        topic + PLATFORMS_SUFFIX, self.link.partition)
        # platforms stand still: their top faces' poses once (yaw as a quaternion about z)
        tops = {name: (np.array([p.center_xy_m[0], p.center_xy_m[1], p.height_m], dtype=float),
                       np.array([math.cos(p.yaw_rad / 2), 0.0, 0.0, math.sin(p.yaw_rad / 2)]))
                for name, p in platforms.items()}
        sizes = {name: (p.size_xy_m[0], p.size_xy_m[1], p.height_m) for name, p in platforms.items()}

        def sample(state: RobotState) -> None:
            if state.base_pos_w_m is None:
                return
            objects = {name: sim.object_pose(name) for name in boxes}
            objects.update(tops)
            for stamp, seen in perception.sample(time.time(), state.base_pos_w_m, state.imu_quat_wxyz, objects):
                if self._perception_writer is not None:
                    self._perception_writer.write(stamp, {name: seen[name] for name in boxes})
                if self._platform_writer is not None:
                    self._platform_writer.write(stamp, {name: (*seen[name], sizes[name]) for name in platforms})

        self.endpoint.state_observers.append(sample)
        self.perception, self.scene_sim = perception, sim
        return perception

    def record_ground_truth(self, sim: MujocoBackend, rate_hz: float = 50.0) -> GroundTruthRecorder:
        """Record where the hands, soles and boxes really are (sim/ground_truth.py) at `rate_hz` of the
        published states, stamped with the host's monotonic clock (as the robot path stamps its states
        and goal records): judge_goal(goal, the deploy's goal record, recorder.arrays()) judges each goal."""
        from g1_control.sim.ground_truth import GroundTruthRecorder

        recorder = GroundTruthRecorder(sim)
        every = max(1, round(1.0 / (self.endpoint.period_s * rate_hz)))
        count = [0]

        def sample(state: RobotState) -> None:
            if count[0] % every == 0:
                recorder.sample(time.monotonic())
            count[0] += 1

        self.endpoint.state_observers.append(sample)
        return recorder

    def start(self) -> RobotEmulator:
        self.endpoint.start()
        return self

    def close(self) -> None:
        self.endpoint.stop()
        for writer in (self._mocap_writer, self._perception_writer, self._platform_writer):
            if writer is not None:
                writer.close()
        if self.service is not None:
            self.service.close()
        self.link.close()
        self.physics.close()

    def report(self) -> dict:
        from dataclasses import asdict

        out = asdict(self.endpoint.counters)
        out["first_damping_time_s"] = self.endpoint.first_damping_time_s
        out["builtin_mode"] = self.service.active_mode if self.service is not None else None
        out["mode"] = self.mode
        out.update(self.endpoint.command_wire_stats())
        out.update(self.endpoint.whole_run_period_stats())
        state = self.physics.read_state()
        out["base_pos_w_m"] = None if state.base_pos_w_m is None else [float(v) for v in state.base_pos_w_m]
        out["base_yaw_rad"] = float(yaw_of(state.imu_quat_wxyz))
        if self.mocap is not None and self._mocap_writer is not None:
            out["mocap"] = {"measured": self.mocap.measured, "dropped": self.mocap.dropped,
                            "sent": self._mocap_writer.sent}
        if self.perception is not None:
            out["perception"] = {"measured": self.perception.measured, "dropped": self.perception.dropped,
                                 "sent": 0 if self._perception_writer is None else self._perception_writer.sent,
                                 "platform_frames_sent": 0 if self._platform_writer is None else self._platform_writer.sent}
        sim = self.scene_sim
        if sim is not None:  # the ground-truth outcome, for judging: where the boxes and the feet are
            out["boxes_w_m"] = {b.name: [float(v) for v in sim.object_pose(b.name)[0]] for b in sim.scene.boxes}
            out["platforms_w_m"] = {p.name: {"center_xy_m": [float(v) for v in p.center_xy_m],
                                             "size_xy_m": [float(v) for v in p.size_xy_m], "height_m": float(p.height_m),
                                             "yaw_rad": float(p.yaw_rad)} for p in sim.scene.platforms}
        out["first_damping_base_pos_w_m"] = self.endpoint.first_damping_base_pos_w_m
        last = self.endpoint.last_command
        # damping on every motor the robot has (a 23-DoF G1's empty slots go out disabled, gains 0)
        motors = g1.VARIANTS.get(int(state.mode_machine), g1.G1_29DOF).active_mask
        out["last_command_is_damping"] = None if last is None else bool(
            float(np.max(last.motor_kp_nm_per_rad)) == 0.0
            and float(np.min(last.motor_kd_nms_per_rad[:g1.NUM_JOINTS][motors])) > 0)
        gantry = self.physics.inner
        self._report_randomization(out, gantry.inner if isinstance(gantry, Gantry) else gantry)
        if isinstance(gantry, Gantry):
            out["gantry_lowered_at_s"] = gantry.lowered_at_s
            out["gantry_lowered_base_pos_w_m"] = (None if gantry.lowered_base_pos_m is None
                                                  else [float(v) for v in gantry.lowered_base_pos_m])
        return out

    @staticmethod
    def _report_randomization(out: dict, physics: Backend) -> None:
        """The simulated robot's randomisation (sim/randomize.py) as drawn and as its model holds it."""
        if getattr(physics, "draw", None) is None:
            # Not a randomised MuJoCo robot. Importing MuJoCo here (a mock robot's first report) held the
            # interpreter for tens of ms while the link thread waited: the fault suite's first damping
            # frame was stamped 17-70 ms late (later ones 1-3 ms).
            return
        from g1_control.sim.mujoco_backend import MujocoBackend

        if not isinstance(physics, MujocoBackend) or physics.draw is None:
            return
        m = physics.model
        robot = m.body(g1.BASE_BODY).id
        out["randomize"] = {**physics.draw.as_dict(), "latency_applied_s": physics.latency_s,
                            "describe": physics.describe(),
                            "robot_mass_kg": float(sum(m.body_mass[b] for b in range(1, m.nbody)
                                                       if m.body_rootid[b] == robot))}

    def serve_stdin(self) -> None:
        """Line protocol for test harnesses: '<fault>' -> {'fault', 't_s'}; a remote command (see
        REMOTE_COMMANDS) -> {'remote', 't_s'}; 'report' -> counters, lowcmd wire statistics and (MuJoCo)
        the base position; 'quit' or end of input stops. One JSON object per reply line."""
        for line in sys.stdin:
            word = line.strip()
            if not word:
                continue
            if word == "quit":
                break
            if word == "report":
                reply = self.report()
            elif word.split()[0] in ("press", "hold", "stick"):
                try:
                    reply = {"remote": word, "t_s": self.remote(word)}
                except ValueError as exc:
                    reply = {"error": str(exc)}
            else:
                try:
                    reply = {"fault": word, "t_s": self.inject(word)}
                except ValueError as exc:
                    reply = {"error": str(exc)}
            print(json.dumps(reply), flush=True)


def _start_to_scene(start_in_scene: list[float], pos: np.ndarray, quat_wxyz: np.ndarray
                    ) -> tuple[np.ndarray, np.ndarray]:
    """A pose in the start frame of a robot that started at `start_in_scene` (x, y, yaw), in the scene's frame."""
    from g1_control.sim.mocap import _rot_z

    x, y, yaw = (float(v) for v in start_in_scene)
    c, s = math.cos(yaw), math.sin(yaw)
    return np.array([x + c * pos[0] - s * pos[1], y + s * pos[0] + c * pos[1], pos[2]]), _rot_z(quat_wxyz, yaw)
