"""Keep every link of the G1 out of the floor and out of static scene shapes: each collision
geometry of the robot (robot/collision.py: the URDF's meshes as convex hulls) stays at least
`margin_m` above the floor and outside every convex scene shape (the boxes a climbing sequence
steps on).

The feet are left to GroundLimit, which knows when a foot is held on a support (the IK anchors
stance feet on the floor or a box top); this limit covers the rest of the body, so thighs, knees,
hands and the pelvis stay out of a box the feet climb onto. See mesh_pairs.py for how rows are made.
"""

from __future__ import annotations

from g1_control.ik.limits.collision_limit import CollisionLimit
from g1_control.motion.objects import ObjectShape
from g1_control.robot import g1
from g1_control.robot.collision import StandIn


class SceneCollisionLimit(CollisionLimit):
    def __init__(self, scene: tuple[ObjectShape, ...] = (), ground_height_m: float | None = 0.0,
                 skip_links: tuple[str, ...] = g1.FOOT_BODIES, margin_m: float = 0.002, activation_m: float = 0.03,
                 max_push_m: float = 0.03, stand_ins: tuple[StandIn, ...] | None = None) -> None:
        """ground_height_m: the floor's height, or None for no floor."""
        super().__init__(False, scene, ground_height_m, skip_links, margin_m=margin_m, activation_m=activation_m,
                         max_push_m=max_push_m, stand_ins=stand_ins)
