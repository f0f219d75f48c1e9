"""Forward kinematics of the G1 for whole clips: body poses in the world from root pose + joints.

Bodies are the pelvis and the child link of each of the 29 joints (30 bodies, the set mjlab /
BeyondMimic motion files carry), in this project's joint order; their names travel with every
clip so no reader has to guess an order.
"""

from __future__ import annotations

import functools

import numpy as np

from g1_control import rotations as quat
from g1_control.motion.exceptions import UnknownJointError
from g1_control.robot import description, g1


@functools.cache
def _child_links() -> tuple[str, ...]:
    import pinocchio as pin

    model = description.pinocchio_model()
    names = [g1.BASE_BODY]
    for joint in g1.JOINT_NAMES:
        jid = model.getJointId(joint)
        body = next(f.name for f in model.frames if f.type == pin.FrameType.BODY and f.parentJoint == jid
                    and model.frames[f.parentFrame].name == joint)
        names.append(body)
    return tuple(names)


def default_body_names() -> tuple[str, ...]:
    """pelvis + the child link of each joint in g1.JOINT_NAMES order (30 names)."""
    return _child_links()


def forward_kinematics(root_pos_w_m: np.ndarray, root_quat_wxyz: np.ndarray, joint_pos_rad: np.ndarray,
                       body_names: tuple[str, ...] | None = None) -> tuple[np.ndarray, np.ndarray]:
    """(T, B, 3) positions (m) and (T, B, 4) orientations (w, x, y, z) of the bodies in the world."""
    import pinocchio as pin

    model = description.pinocchio_model()
    data = model.createData()
    names = body_names or default_body_names()
    ids = []
    for name in names:
        if not model.existFrame(name):
            raise UnknownJointError(f"the G1 model has no body '{name}'")
        ids.append(model.getFrameId(name))
    t = joint_pos_rad.shape[0]
    pos = np.empty((t, len(ids), 3))
    rot = np.empty((t, len(ids), 3, 3))
    for k in range(t):
        q = description.pinocchio_q(root_pos_w_m[k], root_quat_wxyz[k], joint_pos_rad[k])
        pin.framesForwardKinematics(model, data, q)
        for j, fid in enumerate(ids):
            placement = data.oMf[fid]
            pos[k, j] = placement.translation
            rot[k, j] = placement.rotation
    quats = quat.from_matrix(rot)
    # from_matrix returns w >= 0; keep each body's sign continuous over time for interpolation.
    for k in range(1, t):
        flip = np.sum(quats[k] * quats[k - 1], axis=-1) < 0
        quats[k, flip] *= -1
    return pos, quats
