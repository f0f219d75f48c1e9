"""The robot's kinematic state for one IK step: pinocchio model + data at a configuration q.

Everything a task or limit reads (frame placements, frame Jacobians, centre of mass and its
Jacobian) is computed once per `update(q)` and shared, so six frame tasks cost one
`computeJointJacobians` rather than six.

Conventions: q is pinocchio's layout (x y z, qx qy qz qw, 29 joints; nq 36); a tangent step
dq has nv = 35 entries (base linear and angular displacement in the base frame, then joints).
Frame Jacobians are LOCAL_WORLD_ALIGNED (linear rows give world-frame point velocity).
"""

from __future__ import annotations

import functools
import math
import xml.etree.ElementTree as ET
from typing import Any

import numpy as np
import pinocchio as pin

from g1_control.ik.exceptions import InvalidConfigurationError, InvalidFrameError
from g1_control.robot import description, g1

FOOT_POINT_FRAMES = ("left_toe", "right_toe", "left_heel", "right_heel", "left_sole", "right_sole")
"""Operational frames this module adds on the feet (see `foot_contact_points`)."""


@functools.cache
def foot_contact_points() -> dict[str, list[tuple[np.ndarray, float]]]:
    """Collision spheres (centre in the foot link frame, radius m) of each foot link, read from
    the URDF itself, so ground contact follows the description rather than a hard-coded offset."""
    root = ET.parse(description.urdf_path()).getroot()
    points: dict[str, list[tuple[np.ndarray, float]]] = {}
    for link in root.iter("link"):
        name = link.get("name")
        if name not in g1.FOOT_BODIES:
            continue
        for col in link.iter("collision"):
            sphere = col.find("geometry/sphere")
            if sphere is None:
                continue
            origin = col.find("origin")
            radius = sphere.get("radius")
            if radius is None:
                raise InvalidFrameError(f"the G1 URDF has a collision sphere without a radius on {name}")
            # URDF: an <origin> without xyz is at the link origin.
            xyz = np.array([float(v) for v in (origin.get("xyz", "0 0 0") if origin is not None else "0 0 0").split()])
            xyz.setflags(write=False)  # shared by every caller (cached)
            points.setdefault(name, []).append((xyz, float(radius)))
    missing = [b for b in g1.FOOT_BODIES if b not in points]
    if missing:
        raise InvalidFrameError(f"the G1 URDF has no collision spheres on {missing}; expected four per foot")
    return points


def sole_depth_m(foot_link: str) -> float:
    """Height of a foot link's origin above its sole when the foot is level (URDF spheres)."""
    return -min(c[2] - r for c, r in foot_contact_points()[foot_link])


def _build_model() -> pin.Model:
    """The shared G1 model plus operational frames on the soles (toe, heel, sole centre)."""
    model = pin.Model(description.pinocchio_model())  # a copy: the cached model stays untouched
    for side, link in zip(("left", "right"), g1.FOOT_BODIES):
        pts = foot_contact_points()[link]
        centres = np.array([c for c, _ in pts])
        radius = max(r for _, r in pts)
        sole_z = centres[:, 2].min() - radius
        parent_frame = model.frames[model.getFrameId(link)]
        toe = np.array([centres[:, 0].max(), 0.0, sole_z])
        heel = np.array([centres[:, 0].min(), 0.0, sole_z])
        sole = np.array([0.0, 0.0, sole_z])  # under the ankle-roll axis: where the foot rests
        for name, p in ((f"{side}_toe", toe), (f"{side}_heel", heel), (f"{side}_sole", sole)):
            placement = parent_frame.placement * pin.SE3(np.eye(3), p)
            model.addFrame(pin.Frame(name, parent_frame.parentJoint, model.getFrameId(link), placement,
                                     pin.FrameType.OP_FRAME))
    return model


_MODEL: pin.Model | None = None


def ik_model() -> pin.Model:
    """The G1 pinocchio model used by the IK (built once per process)."""
    global _MODEL
    if _MODEL is None:
        _MODEL = _build_model()
    return _MODEL


class Configuration:
    """Kinematic quantities of the G1 at one configuration. Call `update(q)` after changing q."""

    def __init__(self, q: np.ndarray | None = None, model: pin.Model | None = None) -> None:
        self.model = model if model is not None else ik_model()
        self.data = self.model.createData()
        self.nq, self.nv = self.model.nq, self.model.nv
        self._frame_ids: dict[str, int] = {}
        self._support_masks: dict[tuple[int, ...], np.ndarray] = {}
        self._joint_masks: np.ndarray | None = None
        self.layout_cache: dict[tuple, Any] = {}
        """Per-task-set data (row layouts) that tasks keep between ticks; keyed by the tasks. The values
        are the tasks' own (g1_control/ik/tasks/frame_task.py: _Layout)."""
        self._com_w_m = np.zeros(3)
        self._com_jacobian = np.zeros((3, self.nv))
        self._com_valid = False
        if q is None:
            q = description.pinocchio_q(np.array([0.0, 0.0, g1.DEFAULT_PELVIS_HEIGHT_M]),
                                        np.array([1.0, 0.0, 0.0, 0.0]), g1.DEFAULT_Q_RAD)
        self.q = np.zeros(self.nq)
        self.update(q)

    def frame_id(self, name: str) -> int:
        """Index of frame `name`; raises InvalidFrameError naming the frame and a few known ones."""
        fid = self._frame_ids.get(name)
        if fid is None:
            if not self.model.existFrame(name):
                known = sorted({f.name for f in self.model.frames if f.type in (pin.FrameType.BODY,
                                                                               pin.FrameType.OP_FRAME)})
                raise InvalidFrameError(f"the G1 model has no frame '{name}'; known frames: {', '.join(known)}")
            fid = self.model.getFrameId(name)
            self._frame_ids[name] = fid
        return fid

    def check_q(self, q: np.ndarray) -> np.ndarray:
        q = np.asarray(q, dtype=float)
        if q.shape != (self.nq,):
            raise InvalidConfigurationError(f"configuration has shape {q.shape}; expected ({self.nq},) "
                                            "(pinocchio layout: x y z, qx qy qz qw, 29 joints)")
        if not np.isfinite(q).all():
            raise InvalidConfigurationError("configuration contains NaN or inf")
        quat = q[3:7]
        norm = math.sqrt(quat @ quat)
        if abs(norm - 1.0) > 1e-3:
            raise InvalidConfigurationError(f"base quaternion has norm {norm:.4f}; expected 1")
        return q

    def update(self, q: np.ndarray | None = None, check: bool = True) -> None:
        """Recompute placements, joint Jacobians and the centre of mass (+ Jacobian) at q.
        check=False skips validation, for configurations this module produced itself."""
        if q is not None:
            self.q[:] = self.check_q(q) if check else q
            quat = self.q[3:7]
            quat /= math.sqrt(quat @ quat)
        pin.computeJointJacobians(self.model, self.data, self.q)
        pin.updateFramePlacements(self.model, self.data)
        self._com_valid = False  # computed on first use: many IK setups have no CoM task

    def _update_com(self) -> None:
        # jacobianCenterOfMass also fills data.com[0]; no second forward pass needed.
        self._com_jacobian[:] = pin.jacobianCenterOfMass(self.model, self.data, self.q, False)
        self._com_w_m[:] = self.data.com[0]
        self._com_valid = True

    @property
    def com_w_m(self) -> np.ndarray:
        """Whole-body centre of mass in the world (m)."""
        if not self._com_valid:
            self._update_com()
        return self._com_w_m

    @property
    def com_jacobian(self) -> np.ndarray:
        """(3, nv) Jacobian of the centre of mass."""
        if not self._com_valid:
            self._update_com()
        return self._com_jacobian

    def frame_placement(self, frame_id: int) -> pin.SE3:
        return self.data.oMf[frame_id]

    def placements(self, frame_ids: list[int]) -> np.ndarray:
        """(K, 4, 4) world placements of the frames (homogeneous matrices)."""
        oMf = self.data.oMf
        return np.array([oMf[f].homogeneous for f in frame_ids])

    def support_masks(self, frame_ids: tuple[int, ...]) -> np.ndarray:
        """(K, nv): 1.0 for the velocity coordinates that move each frame (the supporting joints of
        its parent joint, the floating base included), 0.0 for the rest. With these, a frame's
        Jacobian is read off the world joint Jacobians `data.J` (see ik/kernels.py)."""
        masks = self._support_masks.get(frame_ids)
        if masks is None:
            masks = self.joint_support_masks()[[self.model.frames[fid].parentJoint for fid in frame_ids]]
            self._support_masks[frame_ids] = masks  # shared: callers must not write to it
        return masks

    def joint_support_masks(self) -> np.ndarray:
        """(njoints, nv): support_masks per joint of the model (row 0, the universe: all 0.0)."""
        if self._joint_masks is None:
            masks = np.zeros((self.model.njoints, self.nv))
            for j in range(1, self.model.njoints):
                for joint in self.model.supports[j]:
                    if joint > 0:  # 0 is the universe
                        jm = self.model.joints[joint]
                        masks[j, jm.idx_v:jm.idx_v + jm.nv] = 1.0
            self._joint_masks = masks  # shared: callers must not write to it
        return self._joint_masks

    @property
    def joint_jacobians_w(self) -> np.ndarray:
        """(6, nv) pinocchio's data.J: each column the spatial velocity (world axes, at the world
        origin) its velocity coordinate produces on the joint it belongs to."""
        return self.data.J

    def frame_jacobian(self, frame_id: int) -> np.ndarray:
        """(6, nv) Jacobian, LOCAL_WORLD_ALIGNED: rows 0-2 world linear velocity of the frame
        origin, rows 3-5 world angular velocity."""
        return pin.getFrameJacobian(self.model, self.data, frame_id, pin.LOCAL_WORLD_ALIGNED)

    def integrate(self, dq: np.ndarray) -> np.ndarray:
        """Configuration reached from q along tangent step dq (does not update)."""
        return pin.integrate(self.model, self.q, dq)

    def integrate_inplace(self, dq: np.ndarray) -> None:
        self.update(pin.integrate(self.model, self.q, dq), check=False)

    @property
    def joint_q_rad(self) -> np.ndarray:
        return self.q[7:]
