"""All of the G1's collision rows in one limit: every pair of non-adjacent links kept apart (as
SelfCollisionLimit) and every link but the feet kept above the floor and out of the scene shapes
(as SceneCollisionLimit). One limit rather than two so that each step places the geometries and
bounds the gaps once (the retargeter's choice; the two presets remain for use on their own)."""

from __future__ import annotations

from g1_control.ik.limits.mesh_pairs import MeshPairLimit
from g1_control.motion.objects import ObjectShape
from g1_control.robot import description, g1
from g1_control.robot.collision import StandIn, ik_self_pairs, ik_stand_ins, non_adjacent_pairs


class CollisionLimit(MeshPairLimit):
    def __init__(self, self_collision: bool = True, scene: tuple[ObjectShape, ...] = (),
                 ground_height_m: float | None = 0.0, skip_links: tuple[str, ...] = g1.FOOT_BODIES,
                 margin_m: float = 0.002, activation_m: float = 0.03, max_push_m: float = 0.03,
                 stand_ins: tuple[StandIn, ...] | None = None) -> None:
        """self_collision: the self pairs (those that can meet, robot.collision.ik_self_pairs; every
        non-adjacent pair for stand-ins given here); scene and ground_height_m (None: no floor): the
        shapes every link but `skip_links` stays out of."""
        if stand_ins is None:
            stand_ins, pairs = ik_stand_ins(), ik_self_pairs()
        else:
            pairs = non_adjacent_pairs(description.pinocchio_model().parents, [s.joint for s in stand_ins])
        pairs = pairs if self_collision else []
        geoms = [k for k, g in enumerate(stand_ins) if g.link not in skip_links]
        count = len(scene) + (ground_height_m is not None)
        super().__init__(pairs, [(k, s) for k in geoms for s in range(count)], shapes=tuple(scene),
                         floor_height_m=ground_height_m, margin_m=margin_m, activation_m=activation_m,
                         max_push_m=max_push_m, stand_ins=stand_ins)
