"""Keep the G1's body parts from passing through each other: every self-collision pair of the
robot's collision geometries (robot/collision.py: each pair of links not joined by one joint, the
URDF's meshes as convex hulls) stays at least `margin_m` apart.

The same geometries and pairs the clip checker measures (retarget/clip_geometry.py), so a clip the
IK produced has no self-collision the checker could find beyond the linearisation error of a step.
Rows come only for pairs that may be within `activation_m` (bounding capsules first, then coal's
exact distance), so far-apart limbs cost one compiled pass; see mesh_pairs.py.
"""

from __future__ import annotations

from g1_control.ik.limits.mesh_pairs import MeshPairLimit
from g1_control.robot.collision import CollisionModel, collision_model


class SelfCollisionLimit(MeshPairLimit):
    def __init__(self, margin_m: float = 0.002, activation_m: float = 0.03, max_push_m: float = 0.03,
                 model: CollisionModel | None = None) -> None:
        model = model or collision_model()
        super().__init__([tuple(p) for p in model.self_pairs.tolist()], margin_m=margin_m,
                         activation_m=activation_m, max_push_m=max_push_m, model=model)
