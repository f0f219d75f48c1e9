"""Keep the G1's body parts from passing through each other: every self-collision pair of the
robot's collision geometries (robot/collision.py: each pair of links not joined by one joint, the
URDF's meshes as convex hulls) stays at least `margin_m` apart.

The same geometries and pairs the clip checker measures (retarget/clip_geometry.py; the IK uses
stand-ins that hold them, robot.collision.ik_stand_ins), so a clip the IK produced has no
self-collision the checker could find beyond the linearisation error of a step. Rows come only for
pairs that may be within `activation_m` (bounding capsules first, then coal's exact distance), so
far-apart limbs cost one compiled pass; see mesh_pairs.py.
"""

from __future__ import annotations

from g1_control.ik.limits.collision_limit import CollisionLimit
from g1_control.robot.collision import StandIn


class SelfCollisionLimit(CollisionLimit):
    def __init__(self, margin_m: float = 0.002, activation_m: float = 0.03, max_push_m: float = 0.03,
                 stand_ins: tuple[StandIn, ...] | None = None) -> None:
        super().__init__(True, (), None, margin_m=margin_m, activation_m=activation_m, max_push_m=max_push_m,
                         stand_ins=stand_ins)
