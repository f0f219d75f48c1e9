"""IK limits: hard constraints on the step."""

from g1_control.ik.limits.base import INF, BoxBounds, Limit, RowConstraint
from g1_control.ik.limits.base_velocity_limit import BaseVelocityLimit
from g1_control.ik.limits.collision_limit import CollisionLimit
from g1_control.ik.limits.contact_limit import ContactLimit
from g1_control.ik.limits.ground_limit import GroundLimit
from g1_control.ik.limits.joint_position_limit import JointPositionLimit
from g1_control.ik.limits.joint_velocity_limit import JointVelocityLimit
from g1_control.ik.limits.mesh_pairs import MeshPairLimit
from g1_control.ik.limits.scene_collision_limit import SceneCollisionLimit
from g1_control.ik.limits.self_collision_limit import SelfCollisionLimit
from g1_control.ik.limits.step_limit import StepLimit
from g1_control.ik.limits.swing_foot_limit import SwingFootLimit, SwingMode

__all__ = [
           "INF",
           "BaseVelocityLimit",
           "BoxBounds",
           "CollisionLimit",
           "ContactLimit",
           "GroundLimit",
           "JointPositionLimit",
           "JointVelocityLimit",
           "Limit",
           "MeshPairLimit",
           "RowConstraint",
           "SceneCollisionLimit",
           "SelfCollisionLimit",
           "StepLimit",
           "SwingFootLimit",
           "SwingMode",
]
