"""`IKRetargeter`: the online stage between the generator and the tracker.

Each tick it turns a KinematicReference (root pose, posture, named frame targets, foot contacts)
into a JointReference the G1 can take, by one or more differential-IK QP steps from the previous
configuration. Tasks: root pose, every named frame target, centre of mass of the reference
posture, posture, damping, temporal smoothness. Limits: joint positions, joint and base velocities
(anchored at the tick's start), stance feet held where they touched down, feet above the ground;
optionally (offline retargeting turns them on) every pair of links apart and every link out of the
floor and the scene (CollisionLimit, the URDF's collision meshes) and free feet off the ground when
they move (SwingFootLimit). Weights and switches come from `IKConfig`.
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
    CollisionLimit,
    ContactLimit,
    GroundLimit,
    JointPositionLimit,
    JointVelocityLimit,
    Limit,
    MeshPairLimit,
    StepLimit,
    SwingFootLimit,
    SwingMode,
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
from g1_control.motion.objects import support_height, support_normal
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
    smoothness_cost: float | tuple[float, ...] = 0.05
    """Scalar, or one cost per tangent direction (35: base linear, base angular, 29 joints)."""
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
    """A foot touching down with its lowest point within this of the ground (or a box's top, a
    ramp) is laid flat on it."""
    touchdown_reach_m: float | None = None
    """A foot touching down further than this above any support is not held (None: held wherever
    it is). Offline retargeting sets it: a performer's contact the G1's foot cannot reach (its foot
    beside the box the human stands on) would otherwise hold the foot in the air."""
    scene: tuple = ()
    """Static shapes (motion.objects.ObjectShape, world coordinates) the feet stand on besides the
    floor: the ground limit keeps feet on their tops and a touchdown snaps onto them."""
    self_collision: bool = False
    """Keep every pair of non-adjacent links apart (SelfCollisionLimit: the URDF's collision meshes);
    off online by default (a generator's references rarely need it), on in offline retargeting."""
    scene_collision: bool | None = None
    """Keep every link (not only the feet) above the floor and out of the scene shapes
    (SceneCollisionLimit); the feet are the ground limit's (enforce_ground). None: on when a `scene`
    is given; offline retargeting turns it on always (the floor too)."""
    contact_tolerance_m: float = 1e-3
    """Held-foot drift above which a projection step puts the foot back (0 disables)."""
    swing_feet: bool = False
    """Free feet near the ground lift clear of it or cross it slowly (SwingFootLimit): no foot slides
    over the ground while the performer's foot is off it. On in offline retargeting."""
    swing_near_m: float = 0.03
    swing_clearance_m: float = 0.025
    swing_max_slide_m: float = 0.009
    collision_tolerance_m: float = 3e-3
    """A collision pair this far inside its margin after the tick's steps gets a projection step too."""
    projection_steps: int = 4
    step_halvings: int = 3
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
        self.smoothness_task = SmoothnessTask(np.asarray(cfg.smoothness_cost, dtype=float), nv)
        self._projection_task = DampingTask(1.0, nv)
        self.frame_tasks: dict[str, FrameTask] = {}
        self.joint_position_limit = JointPositionLimit(margin_rad=cfg.joint_margin_rad)
        self.joint_velocity_limit = JointVelocityLimit(scale=cfg.velocity_limit_scale)
        self.base_velocity_limit = BaseVelocityLimit(cfg.base_max_linear_mps, cfg.base_max_angular_radps)
        self.contacts = [ContactLimit(f, free_yaw=cfg.contact_free_yaw) for f in cfg.contact_frames]
        self.ground_limit = GroundLimit(cfg.ground_height_m, scene=cfg.scene) if cfg.enforce_ground else None
        self._anchored_on_support: dict[str, bool] = {}
        self.swing_limits = ([SwingFootLimit(f, cfg.swing_near_m, cfg.swing_clearance_m, cfg.swing_max_slide_m)
                              for f in cfg.contact_frames] if cfg.swing_feet else [])
        scene_collision = bool(cfg.scene) if cfg.scene_collision is None else cfg.scene_collision
        self.collision_limit = (CollisionLimit(cfg.self_collision, cfg.scene if scene_collision else (),
                                               cfg.ground_height_m if scene_collision else None)
                                if cfg.self_collision or scene_collision else None)
        """Self pairs (IKConfig.self_collision) and links against the floor and scene (scene_collision)."""
        self._mesh_limits: list[MeshPairLimit] = [self.collision_limit] if self.collision_limit is not None else []
        # Limits whose rows come only near contact, and which a large step can therefore miss.
        self._resolvable = self._mesh_limits + ([self.ground_limit] if self.ground_limit is not None and cfg.scene
                                                else [])
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
        self._trust_region: StepLimit | None = None
        self.relaxed_steps = 0
        """Steps solved without the collision rows (the last fallback of _solve_step), since creation."""

    # ------------------------------------------------------------------ helpers
    def reset(self, q: np.ndarray | None = None) -> None:
        """Forget history; start from pinocchio configuration q (default stance) on the next solve."""
        self._initialised = q is not None
        if q is not None:
            self.configuration.update(q)
        for c in self.contacts:
            c.release()
        for swing in self.swing_limits:
            swing.release()
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

    def _touchdown_anchor(self, frame: str) -> pin.SE3 | None:
        """Anchor for a foot starting contact: where it is, or flat on what it stands on when close
        to it (the floor, a box's top, a ramp's slope), or None when it is further above any support
        than `touchdown_reach_m` (a foot cannot stand in the air: it stays free this tick).
        Laying a tilted foot flat pivots it about its sole centre, which keeps its place on the
        ground (pivoting about the ankle would drag the sole by centimetres: measured as sliding)."""
        pose = pin.SE3(self.configuration.frame_placement(self.configuration.frame_id(frame)))
        depth = self._sole_depth[frame]
        centre = self._sole_centre[frame]
        centre_w = pose.rotation @ centre + pose.translation
        # The sole's lowest point over what it stands on decides (a foot on its toes has its sole
        # centre well above the ground: measured 5 cm, and was held hovering 2.5 cm up for a whole
        # stance; on a ramp the heel and the toe stand on different heights).
        cfg = self.config
        spheres = foot_contact_points().get(frame)
        if spheres is None:
            bottoms = np.array([[centre_w[0], centre_w[1], centre_w[2] - (depth + centre[2])]])
        else:
            bottoms = np.array([pose.rotation @ c + pose.translation - [0.0, 0.0, r] for c, r in spheres])
        supports = support_height(cfg.scene, bottoms, cfg.ground_height_m, cfg.ground_snap_m)
        gaps = bottoms[:, 2] - supports
        lowest = float(gaps.min())
        if cfg.touchdown_reach_m is not None and lowest > cfg.touchdown_reach_m:
            return None
        support, normal = support_normal(cfg.scene, np.array([centre_w[0], centre_w[1], supports.max()]),
                                         cfg.ground_height_m, cfg.ground_snap_m)
        self._anchored_on_support[frame] = lowest >= -1e-9
        if cfg.enforce_ground and lowest < cfg.ground_snap_m:
            # flat on the surface, heading kept: z along its normal, x the heading projected onto it
            heading = pose.rotation[:, 0] - (pose.rotation[:, 0] @ normal) * normal
            if np.linalg.norm(heading) < 1e-6:
                heading = np.cross(normal, pose.rotation[:, 1])
            x = heading / np.linalg.norm(heading)
            rot = np.column_stack([x, np.cross(normal, x), normal])
            on_surface = np.array([centre_w[0], centre_w[1], support])  # the sole centre, on it
            pose = pin.SE3(rot, on_surface - rot @ np.array([centre[0], centre[1], -depth]))
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

    def _update_contacts(self, ref: KinematicReference) -> None:
        if not self.config.hold_contacts:
            return
        for flag, contact in zip(np.asarray(ref.contacts, dtype=bool), self.contacts):
            if flag and not contact.active:
                anchor = self._touchdown_anchor(contact.frame)
                if anchor is not None:
                    contact.set_anchor(anchor)
            elif not flag and contact.active:
                contact.release()

    def _plan_swing(self, ref: KinematicReference) -> None:
        """Each free foot's SwingFootLimit mode for this tick (held feet need none)."""
        for swing, contact in zip(self.swing_limits, self.contacts):
            if contact.active:
                swing.release()
                continue
            bottoms = swing.bottoms_w(self.configuration)
            target = ref.frame_targets_w.get(swing.frame)
            target_xy = None if target is None else np.asarray(target)[:2]
            supports = support_height(self.config.scene, bottoms, self.config.ground_height_m,
                                      self.config.ground_snap_m)
            if target_xy is not None and self.config.scene:
                # where the foot is headed too: a ramp rises under a foot moving up it
                ahead = bottoms.copy()
                ahead[:, :2] += target_xy - self.configuration.frame_placement(
                    self.configuration.frame_id(swing.frame)).translation[:2]
                supports = np.maximum(supports, support_height(self.config.scene, ahead, self.config.ground_height_m,
                                                               self.config.ground_snap_m))
            swing.plan(self.configuration, supports, target_xy)

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

    def _limits(self, with_contacts: bool, with_swing: bool = True, with_collisions: bool = True) -> list[Limit]:
        limits: list[Limit] = [self.joint_position_limit, self.joint_velocity_limit, self.base_velocity_limit]
        if self.ground_limit is not None:
            # A held foot's anchor is on or above the ground (see _touchdown_anchor), so the hold
            # keeps it there; its ground rows would be redundant and degenerate.
            self.ground_limit.skip_links = frozenset(
                c.frame for c in self.contacts if with_contacts and c.active and c.frame in g1.FOOT_BODIES
                and self._anchored_on_support.get(c.frame, False))
            limits.append(self.ground_limit)
        if with_collisions:
            limits += self._mesh_limits
        if self._trust_region is not None:
            limits.append(self._trust_region)
        if with_swing:
            limits += [s for s in self.swing_limits if s.mode is not SwingMode.FREE]
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
        """The step under every limit; when that is infeasible, fall back step by step:
        1. the held feet as heavy tasks instead of equalities (e.g. a far touchdown anchor and the
           velocity limits make the exact hold impossible this tick), never skipping a limit;
        2. without the swing-foot rows (a quality rule, not a safety one);
        3. collision pairs already inside their margin only kept from going deeper, not pushed out
           (a held foot against the other shin cannot move away);
        4. without collision rows (last resort, counted in `relaxed_steps`)."""
        cfg = self.config
        try:
            return self.solver.solve(self.configuration, tasks, self._limits(True), cfg.dt_s)
        except NoSolutionFound:
            pass
        self.last_solve_soft_contacts = True
        soft = tasks + self._soft_contact_tasks()
        attempts = [(True, False), (False, False)] if any(s.mode is not SwingMode.FREE for s in self.swing_limits) \
            else [(False, False)]
        for with_swing, relax in attempts + [(False, True)]:
            for lim in self._mesh_limits:
                lim.relaxed = relax
            try:
                return self.solver.solve(self.configuration, soft, self._limits(False, with_swing=with_swing),
                                         cfg.dt_s)
            except NoSolutionFound:
                continue
            finally:
                for lim in self._mesh_limits:
                    lim.relaxed = False
        self.relaxed_steps += 1
        return self.solver.solve(self.configuration, soft, self._limits(False, with_swing=False, with_collisions=False),
                                 cfg.dt_s)

    def _take_step(self, tasks: list[Task]) -> None:
        """One QP step from the current configuration.

        Collision pairs (self-collision, links against the floor and the scene, foot spheres
        against scene shapes) get rows only within their activation distance, but one step may
        carry a pair from beyond it into contact (MeshPairLimit.missed_pairs,
        GroundLimit.missed_pairs: the velocity limits allow 1.2 rad per joint per tick at 30 Hz, a
        foot 10 cm and more). Such a step is solved again from the same configuration with the
        missed pairs in the QP, until no pair is missed. A pair with a row can still end deep
        inside when the step is large (the rows are a linearisation; measured: a wrist 5.7 cm into
        the hip): then the step is solved again inside a trust region, halved up to
        `step_halvings` times, until no pair is more than `collision_tolerance_m` inside."""
        conf = self.configuration
        limits = self._resolvable
        if not limits:
            conf.integrate_inplace(self._solve_step(tasks))
            return
        q_from = conf.q.copy()
        try:
            dq = self._step_catching_missed(tasks, q_from)
            bound = np.abs(dq)
            for _ in range(self.config.step_halvings):
                if not self._collision_too_deep():
                    break
                bound = 0.5 * bound
                self._trust_region = StepLimit(bound + 1e-9)
                conf.update(q_from, check=False)
                try:
                    dq = self._step_catching_missed(tasks, q_from)
                except NoSolutionFound:
                    conf.update(q_from, check=False)
                    conf.integrate_inplace(dq)
                    break
        finally:
            self._trust_region = None
            for lim in limits:
                lim.include[:] = False

    def _step_catching_missed(self, tasks: list[Task], q_from: np.ndarray) -> np.ndarray:
        """Solve and take a step from q_from, solving again while a pair it carries into contact had
        no row (see _take_step); return the step taken. The pairs stay in `include`."""
        conf = self.configuration
        limits = self._resolvable
        dq = self._solve_step(tasks)
        conf.integrate_inplace(dq)
        missed = [lim.missed_pairs(conf) & ~lim.include for lim in limits]
        while any(m.any() for m in missed):  # each round adds pairs to `include`: finitely many rounds
            for lim, m in zip(limits, missed):
                lim.include |= m
            conf.update(q_from, check=False)
            try:
                new = self._solve_step(tasks)
            except NoSolutionFound:
                # No step keeps these pairs apart within the other limits this tick: take the last
                # step that met those (the pairs are active from the next step on).
                conf.integrate_inplace(dq)
                return dq
            dq = new
            conf.integrate_inplace(dq)
            missed = [lim.missed_pairs(conf) & ~lim.include for lim in limits]
        return dq

    def _collision_too_deep(self) -> bool:
        tol = self.config.collision_tolerance_m
        if (self.ground_limit is not None and self.config.scene
                and self.ground_limit.deepest_in_scene(self.configuration) < -tol):
            return True
        return any(lim.deepest(self.configuration) < lim.margin_m - tol for lim in self._mesh_limits)

    def _needs_projection(self) -> bool:
        tol = self.config.contact_tolerance_m
        if tol > 0 and any(c.active and c.position_drift(self.configuration) > tol for c in self.contacts):
            return True
        return self._collision_too_deep()

    def _project(self) -> None:
        """A QP step is a linearisation: a held foot drifts by ~L*theta^2/2 when the leg turns by
        theta in one step (measured: 1-4 cm per frame on fast climbing mocap), and a collision pair
        with a row can still end the step inside its margin (measured: 1-2 cm, arm against thigh;
        6 cm, a foot turning as it swung 12 cm past a box's edge).
        When the drift exceeds `contact_tolerance_m` or a pair is more than `collision_tolerance_m`
        inside its margin, take up to `projection_steps` more steps with no task but a small-motion
        cost, under the same limits: a Newton projection back onto the constraints."""
        for _ in range(self.config.projection_steps):
            if not self._needs_projection():
                return
            try:
                self._take_step([self._projection_task])
            except NoSolutionFound:
                return  # the limits allow no projection this tick: keep the QP's result

    # ------------------------------------------------------------------ the stage
    def step(self, ref: KinematicReference, q_start: np.ndarray) -> np.ndarray:
        """Run the tick's QP iterations from pinocchio configuration q_start; return the new q."""
        cfg = self.config
        conf = self.configuration
        conf.update(q_start)
        self.joint_velocity_limit.set_anchor(q_start[7:])
        self.base_velocity_limit.set_anchor(q_start)
        self._update_contacts(ref)
        self._plan_swing(ref)
        tasks = self._set_targets(ref)
        self.smoothness_task.set_previous_step(self._last_step / cfg.iterations, check=False)
        self.last_solve_soft_contacts = False
        try:
            for _ in range(cfg.iterations):
                self._take_step(tasks)
        except NoSolutionFound:
            # No step even relaxed: the next tick starts from this one's start (the base where the last
            # good solve left it), not from a partly taken step. The caller decides (the loop holds).
            conf.update(q_start, check=False)
            raise
        self._project()
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
