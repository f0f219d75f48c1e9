"""`IKRetargeter`: the online stage between the generator and the tracker.

Each tick it turns a KinematicReference (root pose, posture, named frame targets, foot contacts)
into a JointReference the G1 can take, by one or more differential-IK QP steps from the previous
configuration. Tasks: root pose, every named frame target, centre of mass of the reference
posture, posture, damping, temporal smoothness. Limits: joint positions, joint and base velocities
(anchored at the tick's start), stance feet held where they touched down, feet above the ground.
Weights and switches come from `IKConfig`.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pinocchio as pin

from g1_control.ik import kernels
from g1_control.ik.configuration import Configuration, foot_contact_points, sole_depth_m
from g1_control.ik.exceptions import InvalidReferenceError, NoSolutionFound, TaskDefinitionError
from g1_control.ik.limits import (
    BaseVelocityLimit,
    ContactLimit,
    GroundLimit,
    JointPositionLimit,
    JointVelocityLimit,
    Limit,
    SelfCollisionLimit,
)
from g1_control.ik.solver import BACKENDS, QPSolver
from g1_control.ik.tasks import (
    ComTask,
    DampingTask,
    FrameTask,
    PostureTask,
    SmoothnessTask,
    Task,
)
from g1_control.interfaces import Retargeter
from g1_control.motion.objects import support_height
from g1_control.robot import description, g1
from g1_control.types import JointReference, KinematicReference


@dataclass
class IKConfig:
    """Weights (costs are 1/error-unit: 1/m for positions, 1/rad for angles) and switches."""

    dt_s: float = 0.02
    """Tick length; the 50 Hz IK rate of the loop."""
    iterations: int = 1
    """QP steps per tick. One is enough online (the target moves little per tick)."""
    backend: str = "daqp"
    root_cost: tuple[float, float] = (10.0, 5.0)
    """(position, orientation) cost of the pelvis following the reference root pose; 0 disables."""
    frame_costs: dict[str, tuple[float, float]] = field(default_factory=dict)
    """Per-frame (position, orientation) costs for KinematicReference.frame_targets_w."""
    default_frame_cost: tuple[float, float] = (5.0, 1.0)
    """Costs of a frame target not listed in frame_costs."""
    com_cost: tuple[float, float, float] = (2.0, 2.0, 0.0)
    """Per world axis: CoM follows the CoM of the reference posture (x, y only by default)."""
    posture_cost: float | tuple[float, ...] = 0.3
    """Scalar, or one cost per joint (29) in g1.JOINT_NAMES order."""
    damping_cost: float = 1e-3
    smoothness_cost: float = 0.05
    lm_damping: float = 0.0
    velocity_limit_scale: float = 1.0
    """Fraction of the motors' velocity limits (g1.VELOCITY_LIMIT_RADPS) the IK may use."""
    joint_margin_rad: float = 0.0
    base_max_linear_mps: float = 3.0
    base_max_angular_radps: float = 8.0
    hold_contacts: bool = True
    contact_frames: tuple[str, str] = g1.FOOT_BODIES
    contact_free_yaw: bool = False
    """Stance feet may pivot about the vertical (ContactLimit.free_yaw)."""
    enforce_ground: bool = True
    ground_height_m: float = 0.0
    ground_snap_m: float = 0.03
    """A foot touching down with its sole within this of the ground is put on it, level."""
    scene: tuple = ()
    """Static shapes (motion.objects.ObjectShape, world coordinates) the feet stand on besides the
    floor: the ground limit keeps feet on their tops and a touchdown snaps onto them."""
    self_collision: bool = False
    """Keep arms out of the torso and the legs apart (SelfCollisionLimit); off online by default
    (a generator's references rarely need it and it costs rows), on in offline retargeting."""
    contact_tolerance_m: float = 1e-3
    """Held-foot drift above which a projection step puts the foot back (0 disables)."""
    soft_contact_cost: float = 100.0

    """Cost of the contact when the hard hold is infeasible in a tick (then held as a task)."""

    def validate(self) -> IKConfig:
        if not self.dt_s > 0:
            raise TaskDefinitionError(f"IKConfig.dt_s must be > 0. Got {self.dt_s}")
        if self.iterations < 1:
            raise TaskDefinitionError(f"IKConfig.iterations must be >= 1. Got {self.iterations}")
        if self.backend not in BACKENDS:
            raise TaskDefinitionError(f"IKConfig.backend must be one of {BACKENDS}. Got '{self.backend}'")
        if len(self.contact_frames) != 2:
            raise TaskDefinitionError(f"IKConfig.contact_frames must name (left, right) feet. Got {self.contact_frames}")
        return self


def _quat_xyzw_to_wxyz(q: np.ndarray) -> np.ndarray:
    return np.array([q[3], q[0], q[1], q[2]])


class IKRetargeter(Retargeter):
    """Retargeter (interfaces.Retargeter) on pinocchio + a QP per tick. Not thread-safe."""

    def __init__(self, config: IKConfig | None = None) -> None:
        self.config = (config or IKConfig()).validate()
        cfg = self.config
        kernels.warm_up()
        self.configuration = Configuration()
        self._ref_model = self.configuration.model
        self._ref_data = self._ref_model.createData()
        nv = self.configuration.nv
        self.solver = QPSolver(nv, cfg.backend)
        self.root_task = FrameTask(g1.BASE_BODY, cfg.root_cost[0], cfg.root_cost[1], lm_damping=cfg.lm_damping)
        self.com_task = ComTask(np.asarray(cfg.com_cost))
        self.posture_task = PostureTask(np.asarray(cfg.posture_cost, dtype=float))
        self.damping_task = DampingTask(cfg.damping_cost, nv)
        self.smoothness_task = SmoothnessTask(cfg.smoothness_cost, nv)
        self._projection_task = DampingTask(1.0, nv)
        self.frame_tasks: dict[str, FrameTask] = {}
        self.joint_position_limit = JointPositionLimit(margin_rad=cfg.joint_margin_rad)
        self.joint_velocity_limit = JointVelocityLimit(scale=cfg.velocity_limit_scale)
        self.base_velocity_limit = BaseVelocityLimit(cfg.base_max_linear_mps, cfg.base_max_angular_radps)
        self.contacts = [ContactLimit(f, free_yaw=cfg.contact_free_yaw) for f in cfg.contact_frames]
        self.ground_limit = GroundLimit(cfg.ground_height_m, scene=cfg.scene) if cfg.enforce_ground else None
        self._anchored_on_support: dict[str, bool] = {}
        self.self_collision_limit = SelfCollisionLimit() if cfg.self_collision else None
        spheres = foot_contact_points()
        # Height of a frame's origin above its sole when the foot is level (from the URDF spheres).
        self._sole_depth = {}
        # Centre of the sole (mean of the contact spheres, in the foot frame): the point a
        # touchdown keeps in place while the foot is laid flat.
        self._sole_centre = {}
        for frame in cfg.contact_frames:
            if frame not in spheres:
                self._sole_depth[frame] = 0.0
                self._sole_centre[frame] = np.zeros(3)
            else:
                self._sole_depth[frame] = sole_depth_m(frame)
                self._sole_centre[frame] = np.mean([c for c, _ in spheres[frame]], axis=0)
        self._initialised = False
        self._last_step = np.zeros(nv)
        self.last_solve_soft_contacts = False

    # ------------------------------------------------------------------ helpers
    def reset(self, q: np.ndarray | None = None) -> None:
        """Forget history; start from pinocchio configuration q (default stance) on the next solve."""
        self._initialised = q is not None
        if q is not None:
            self.configuration.update(q)
        for c in self.contacts:
            c.release()
        self._last_step[:] = 0.0

    def _frame_task(self, name: str) -> FrameTask:
        task = self.frame_tasks.get(name)
        if task is None:
            self.configuration.frame_id(name)  # unknown names fail here, with the list of known ones
            pos, ori = self.config.frame_costs.get(name, self.config.default_frame_cost)
            task = FrameTask(name, pos, ori, lm_damping=self.config.lm_damping)
            self.frame_tasks[name] = task
        return task

    @staticmethod
    def _check_reference(ref: KinematicReference) -> None:
        arrays = (ref.root_pos_w_m, ref.root_quat_wxyz, ref.q_rad)
        try:
            flat = np.concatenate(arrays)
        except ValueError:  # one of them is not one-dimensional
            flat = None
        if flat is None or flat.shape != (7 + g1.NUM_JOINTS,) or not np.isfinite(flat).all() \
                or (np.shape(arrays[0]), np.shape(arrays[1])) != ((3,), (4,)):
            # Slow path only on failure: find the field to name.
            for name, expected in (("root_pos_w_m", (3,)), ("root_quat_wxyz", (4,)), ("q_rad", (g1.NUM_JOINTS,))):
                arr = np.asarray(getattr(ref, name))
                if arr.shape != expected:
                    raise InvalidReferenceError(f"KinematicReference.{name} has shape {arr.shape}; expected {expected}")
                if not np.all(np.isfinite(arr)):
                    raise InvalidReferenceError(f"KinematicReference.{name} contains NaN or inf (t = {ref.t_s} s)")
        assert flat is not None  # a field that does not concatenate has the wrong shape: raised above
        if not flat[3:7].any():
            raise InvalidReferenceError(f"KinematicReference.root_quat_wxyz is zero at t = {ref.t_s} s; "
                                        "expected a unit quaternion (qw qx qy qz)")
        if np.asarray(ref.contacts).shape != (2,):
            raise InvalidReferenceError(f"KinematicReference.contacts has shape {np.asarray(ref.contacts).shape}; "
                                        "expected (2,) = (left, right)")
        if ref.frame_targets_w:
            try:
                poses = np.array(list(ref.frame_targets_w.values()), dtype=float)
                fine = poses.shape[1:] == (7,) and np.isfinite(poses).all() and poses[:, 3:].any(axis=1).all()
            except ValueError:  # ragged: one of them has the wrong length
                fine = False
            if not fine:
                for frame, pose in ref.frame_targets_w.items():
                    pose = np.asarray(pose, dtype=float)
                    if pose.shape != (7,) or not np.all(np.isfinite(pose)):
                        raise InvalidReferenceError(
                            f"frame target '{frame}' must be 7 finite numbers (x y z qw qx qy qz); "
                            f"got shape {pose.shape} at t = {ref.t_s} s")
                    if not pose[3:].any():
                        raise InvalidReferenceError(
                            f"frame target '{frame}' has a zero quaternion at t = {ref.t_s} s; "
                            "expected a unit quaternion (qw qx qy qz)")

    def _start_configuration(self, ref: KinematicReference, q_prev: np.ndarray) -> np.ndarray:
        q_prev = np.asarray(q_prev, dtype=float)
        if q_prev.shape == (self.configuration.nq,):
            return q_prev.copy()
        if q_prev.shape != (g1.NUM_JOINTS,):
            raise InvalidReferenceError(f"q_prev has shape {q_prev.shape}; expected ({g1.NUM_JOINTS},) joint angles "
                                        f"or ({self.configuration.nq},) pinocchio configuration")
        if not np.all(np.isfinite(q_prev)):
            raise InvalidReferenceError("q_prev contains NaN or inf")
        if not self._initialised:
            return description.pinocchio_q(ref.root_pos_w_m, ref.root_quat_wxyz / np.linalg.norm(ref.root_quat_wxyz),
                                           q_prev)
        q = self.configuration.q.copy()
        q[7:] = q_prev
        return q

    def _touchdown_anchor(self, frame: str) -> pin.SE3:
        """Anchor for a foot starting contact: where it is, or flat on the ground when close to it.
        Laying a tilted foot flat pivots it about its sole centre, which keeps its place on the
        ground (pivoting about the ankle would drag the sole by centimetres: measured as sliding)."""
        pose = pin.SE3(self.configuration.frame_placement(self.configuration.frame_id(frame)))
        depth = self._sole_depth[frame]
        centre = self._sole_centre[frame]
        centre_w = pose.rotation @ centre + pose.translation
        sole_height = centre_w[2] - (depth + centre[2])
        support = self._support_under(centre_w, sole_height)
        self._anchored_on_support[frame] = sole_height >= support - 1e-9
        if self.config.enforce_ground and sole_height - support < self.config.ground_snap_m:
            yaw = np.arctan2(pose.rotation[1, 0], pose.rotation[0, 0])
            level = pin.utils.rpyToMatrix(0.0, 0.0, yaw)
            origin = centre_w - level @ centre
            origin[2] = support + depth
            pose = pin.SE3(level, origin)
            self._anchored_on_support[frame] = True
        return self._out_of_scene(frame, pose)

    def _out_of_scene(self, frame: str, pose: pin.SE3) -> pin.SE3:
        """Move a touchdown anchor out of the scene shapes: a held foot keeps no ground rows, so an
        anchor that starts 1 cm inside a box's side would stay there for the whole stance."""
        spheres = foot_contact_points().get(frame)
        if not self.config.scene or spheres is None:
            return pose
        centres = np.array([c for c, _ in spheres])
        radii = np.array([r for _, r in spheres])
        for _ in range(3):  # a corner can need one push per face
            world = centres @ pose.rotation.T + pose.translation
            worst, push = -1e-6, None  # touching (clearance 0 to rounding) is fine
            for shape in self.config.scene:
                distance, face = shape.nearest_face(world)
                clearance = distance - radii
                k = int(clearance.argmin())
                if clearance[k] < worst:
                    worst, push = float(clearance[k]), shape.planes[face[k], :3]
            if push is None:
                break
            pose = pin.SE3(pose.rotation, pose.translation - (worst - 1e-4) * push)
        return pose

    def _support_under(self, point_w: np.ndarray, sole_height: float) -> float:
        """Height of the floor, or of a scene shape's top, under a sole at (point x, y, sole_height)."""
        if not self.config.scene:
            return self.config.ground_height_m
        bottom = np.array([[point_w[0], point_w[1], sole_height]])
        # a top at most ground_snap_m above the sole still counts: the touchdown snaps up onto it
        return float(support_height(self.config.scene, bottom, self.config.ground_height_m,
                                    self.config.ground_snap_m)[0])

    def _update_contacts(self, ref: KinematicReference) -> None:
        if not self.config.hold_contacts:
            return
        for flag, contact in zip(np.asarray(ref.contacts, dtype=bool), self.contacts):
            if flag and not contact.active:
                contact.set_anchor(self._touchdown_anchor(contact.frame))
            elif not flag and contact.active:
                contact.release()

    def _set_targets(self, ref: KinematicReference) -> list[Task]:
        cfg = self.config
        tasks: list[Task] = [self.posture_task, self.damping_task, self.smoothness_task]
        self.posture_task.set_target(np.asarray(ref.q_rad, dtype=float), check=False)
        if any(cfg.root_cost) and g1.BASE_BODY not in ref.frame_targets_w:
            self.root_task.set_target_vector(np.concatenate([ref.root_pos_w_m, ref.root_quat_wxyz]))
            tasks.append(self.root_task)
        for name, pose in ref.frame_targets_w.items():
            task = self._frame_task(name)
            task.set_target_vector(pose)  # checked in _check_reference
            tasks.append(task)
        if any(cfg.com_cost):
            q_ref = description.pinocchio_q(ref.root_pos_w_m, ref.root_quat_wxyz / np.linalg.norm(ref.root_quat_wxyz),
                                            ref.q_rad)
            self.com_task.set_target(pin.centerOfMass(self._ref_model, self._ref_data, q_ref, False), check=False)
            tasks.append(self.com_task)
        return tasks

    def _limits(self, with_contacts: bool) -> list[Limit]:
        limits: list[Limit] = [self.joint_position_limit, self.joint_velocity_limit, self.base_velocity_limit]
        if self.ground_limit is not None:
            # A held foot's anchor is on or above the ground (see _touchdown_anchor), so the hold
            # keeps it there; its ground rows would be redundant and degenerate.
            self.ground_limit.skip_links = frozenset(
                c.frame for c in self.contacts if with_contacts and c.active and c.frame in g1.FOOT_BODIES
                and self._anchored_on_support.get(c.frame, False))
            limits.append(self.ground_limit)
        if self.self_collision_limit is not None:
            limits.append(self.self_collision_limit)
        if with_contacts:
            limits += [c for c in self.contacts if c.active]
        return limits

    def _soft_contact_tasks(self) -> list[Task]:
        tasks: list[Task] = []
        for contact in self.contacts:
            if contact.active:
                task = FrameTask(contact.frame, self.config.soft_contact_cost, self.config.soft_contact_cost)
                task.set_target(contact.anchor)
                tasks.append(task)
        return tasks

    def _solve_step(self, tasks: list[Task]) -> np.ndarray:
        cfg = self.config
        try:
            return self.solver.solve(self.configuration, tasks, self._limits(True), cfg.dt_s)
        except NoSolutionFound:
            # Holding the feet exactly is impossible this tick (e.g. a far touchdown anchor
            # and the velocity limits): hold them as heavy tasks instead, never skip the limits.
            self.last_solve_soft_contacts = True
            return self.solver.solve(self.configuration, tasks + self._soft_contact_tasks(), self._limits(False),
                                     cfg.dt_s)

    def _take_step(self, tasks: list[Task]) -> None:
        """One QP step from the current configuration.

        Self-collision pairs get rows only within the limit's activation distance, but one step
        may carry a pair from beyond it into contact (SelfCollisionLimit.missed_pairs: the
        velocity limits allow 1.2 rad per joint per tick at 30 Hz). Such a step is solved again
        from the same configuration with the missed pairs in the QP, until no pair is missed."""
        conf = self.configuration
        limit = self.self_collision_limit
        q_from = conf.q.copy() if limit is not None else None
        dq = self._solve_step(tasks)
        conf.integrate_inplace(dq)
        if limit is None:
            return
        try:
            missed = limit.missed_pairs(conf)
            while missed.any():  # each round adds a pair to `include`: at most len(pairs) rounds
                limit.include |= missed
                conf.update(q_from, check=False)
                try:
                    dq = self._solve_step(tasks)
                except NoSolutionFound:
                    # No step keeps these pairs apart within the other limits this tick: take the
                    # last step that met those (the pairs are active from the next step on).
                    conf.integrate_inplace(dq)
                    return
                conf.integrate_inplace(dq)
                missed = limit.missed_pairs(conf) & ~limit.include
        finally:
            limit.include[:] = False

    def _project_onto_contacts(self) -> None:
        """A QP step is a linearisation: a held foot drifts by ~L*theta^2/2 when the leg turns by
        theta in one step (measured: 1-4 cm per frame on fast climbing mocap). When the drift
        exceeds `contact_tolerance_m`, take one more step with no task but a small-motion cost,
        under the same limits: a Newton projection back onto the contacts."""
        tol = self.config.contact_tolerance_m
        if tol <= 0 or not any(c.active and c.position_drift(self.configuration) > tol for c in self.contacts):
            return
        try:
            dq = self.solver.solve(self.configuration, [self._projection_task], self._limits(True), self.config.dt_s)
        except NoSolutionFound:
            return  # the limits allow no projection this tick: keep the QP's result
        self.configuration.integrate_inplace(dq)

    # ------------------------------------------------------------------ the stage
    def step(self, ref: KinematicReference, q_start: np.ndarray) -> np.ndarray:
        """Run the tick's QP iterations from pinocchio configuration q_start; return the new q."""
        cfg = self.config
        conf = self.configuration
        conf.update(q_start)
        self.joint_velocity_limit.set_anchor(q_start[7:])
        self.base_velocity_limit.set_anchor(q_start)
        self._update_contacts(ref)
        tasks = self._set_targets(ref)
        self.smoothness_task.set_previous_step(self._last_step / cfg.iterations, check=False)
        self.last_solve_soft_contacts = False
        for _ in range(cfg.iterations):
            self._take_step(tasks)
        self._project_onto_contacts()
        self._last_step = pin.difference(conf.model, q_start, conf.q)
        self._initialised = True
        return conf.q.copy()

    def solve(self, reference: KinematicReference, q_prev: np.ndarray) -> JointReference:
        """q_prev: the previous tick's 29 joint angles (rad; the base continues from the last
        solve, or starts at the reference root), or a full pinocchio configuration (36,)."""
        self._check_reference(reference)
        q_start = self._start_configuration(reference, q_prev)
        q_new = self.step(reference, q_start)
        dt = self.config.dt_s
        # The commanded root twist (heading frame) passes through: it is what a walking tracker
        # follows; the IK's own base motion is in the returned root pose.
        return JointReference(
            t_s=reference.t_s,
            q_rad=q_new[7:].copy(),
            dq_radps=self._last_step[6:] / dt,
            root_pos_w_m=q_new[:3].copy(),
            root_quat_wxyz=_quat_xyzw_to_wxyz(q_new[3:7]),
            root_linvel_h_mps=np.array(reference.root_linvel_h_mps, dtype=float),
            root_angvel_h_radps=np.array(reference.root_angvel_h_radps, dtype=float),
            contacts=np.array([c.active for c in self.contacts]) if self.config.hold_contacts
            else np.asarray(reference.contacts, dtype=bool).copy(),
            upper_body_override=reference.upper_body_override,
        )
