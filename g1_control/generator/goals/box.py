"""Where the robot stands to pick a box up or set it down, and where its hands go.

A box is picked from the side of its support nearest to it (a table's edge, or anywhere around a
box on the floor), the robot facing the box square on, its pelvis GRASP_DISTANCE_M behind the
box's centre; both hands on the box's side faces (across the robot's heading), palms in. A box is
set down on a table/platform from its edge nearest to the robot, its centre PLACE_INSET_M inside
that edge (the box's half depth plus a margin), or at a given point.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from g1_control.generator.goals.poses import HAND_FACE_OFFSET_M, ReachRefused
from g1_control.scene import FLOOR, Block, Box, SceneConfig

GRASP_DISTANCE_M = 0.40
"""From the pelvis to the box's centre, horizontally, when picking or placing."""
MIN_EDGE_CLEARANCE_M = 0.18
"""The trunk needs this much room in front of the pelvis at table height."""
PELVIS_TO_STANCE_MID_M = 0.034
"""The middle of the soles is this far ahead of the pelvis when standing."""
PLACE_MARGIN_M = 0.03


@dataclass
class Approach:
    """A stance to work from: the middle of the soles (world xy) and the heading."""

    mid_xy: np.ndarray
    heading: float
    note: str = ""

    def pelvis_xy(self) -> np.ndarray:
        return self.mid_xy - PELVIS_TO_STANCE_MID_M * np.array([math.cos(self.heading), math.sin(self.heading)])


def edge_normal(block: Block, xy_w: np.ndarray) -> tuple[np.ndarray, float]:
    """The outward normal (world) of the block's side nearest to a point on its top, and how far
    inside that side the point is."""
    local = block.local_xy(xy_w)
    half = block.half
    gaps = [half[0] - local[0], half[0] + local[0], half[1] - local[1], half[1] + local[1]]
    k = int(np.argmin(gaps))
    n_local = [np.array([1.0, 0.0]), np.array([-1.0, 0.0]), np.array([0.0, 1.0]), np.array([0.0, -1.0])][k]
    c, s = math.cos(block.yaw_rad), math.sin(block.yaw_rad)
    return np.array([c * n_local[0] - s * n_local[1], s * n_local[0] + c * n_local[1]]), float(gaps[k])


def approach_for(center_xy: np.ndarray, normal_xy: np.ndarray) -> Approach:
    """Facing -normal, the pelvis GRASP_DISTANCE_M from center_xy."""
    n = normal_xy / np.linalg.norm(normal_xy)
    heading = math.atan2(-n[1], -n[0])
    pelvis = center_xy + GRASP_DISTANCE_M * n
    return Approach(pelvis + PELVIS_TO_STANCE_MID_M * np.array([math.cos(heading), math.sin(heading)]), heading)


def pick_approach(scene: SceneConfig, box: Box, box_xy: np.ndarray, robot_xy: np.ndarray) -> Approach:
    """Where to stand to pick `box` (now at box_xy) up; raises ReachRefused when no side works."""
    if box.stands_on == FLOOR:
        d = robot_xy - box_xy
        n = d / max(float(np.linalg.norm(d)), 1e-6)
        return approach_for(box_xy, n)
    block = scene.block(box.stands_on)
    assert block is not None  # SceneConfig.validate checked it
    normal, inside = edge_normal(block, box_xy)
    if GRASP_DISTANCE_M - inside < MIN_EDGE_CLEARANCE_M:
        raise ReachRefused(f"box '{box.name}' is {inside:.2f} m inside the edge of '{block.name}': from that edge "
                           f"the pelvis would be {GRASP_DISTANCE_M - inside:.2f} m from the table (needs "
                           f">= {MIN_EDGE_CLEARANCE_M} m)")
    return approach_for(box_xy, normal)


def place_target(scene: SceneConfig, box: Box, target: str | None, point_w: np.ndarray | None,
                 robot_xy: np.ndarray) -> tuple[np.ndarray, Approach]:
    """(box centre when set down, where to stand) for a place goal."""
    if target is None or target == FLOOR:
        if point_w is None:
            raise ReachRefused("a place goal needs a table/platform or a point")
        center = np.array([point_w[0], point_w[1], box.size[2] / 2])
        d = robot_xy - center[:2]
        return center, approach_for(center[:2], d / max(float(np.linalg.norm(d)), 1e-6))
    block = scene.block(target)
    if block is None:
        raise ReachRefused(f"'{target}' is not a table or platform of the scene")
    if point_w is not None:
        xy = np.asarray(point_w[:2], dtype=float)
        normal, inside = edge_normal(block, xy)
        if GRASP_DISTANCE_M - inside < MIN_EDGE_CLEARANCE_M:
            raise ReachRefused(f"the point is {inside:.2f} m inside the edge of '{target}': out of reach")
    else:
        # the edge that faces the robot, the box centred on it
        local = block.local_xy(robot_xy)
        half = block.half
        ratios = np.abs(local) / half
        axis = int(np.argmax(ratios))
        n_local = np.zeros(2)
        n_local[axis] = math.copysign(1.0, local[axis])
        c, s = math.cos(block.yaw_rad), math.sin(block.yaw_rad)
        normal = np.array([c * n_local[0] - s * n_local[1], s * n_local[0] + c * n_local[1]])
        depth = _extent_along(box, normal) / 2
        edge_mid = block.center + normal * half[axis]
        xy = edge_mid - normal * (depth + PLACE_MARGIN_M)
    center = np.array([xy[0], xy[1], block.height_m + box.size[2] / 2])
    return center, approach_for(xy, normal)


def _extent_along(box: Box, direction: np.ndarray) -> float:
    c, s = math.cos(box.yaw_rad), math.sin(box.yaw_rad)
    ax = np.array([[c, s], [-s, c]])  # the box's x and y axes as rows
    return float(abs(ax[0] @ direction) * box.size[0] + abs(ax[1] @ direction) * box.size[1])


def grasp_width(box: Box, heading: float) -> float:
    """The box's extent across the robot's heading (between the palms)."""
    return _extent_along(box, np.array([-math.sin(heading), math.cos(heading)]))


def hand_points(center_w: np.ndarray, heading: float, width_m: float, gap_m: float, dz_m: float = 0.0,
                ahead_m: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """Left and right hand-frame points beside a box centred at center_w: palms `gap_m` off its
    side faces (negative: pressed in), raised by dz_m, moved ahead_m along the heading."""
    lateral = np.array([-math.sin(heading), math.cos(heading), 0.0])
    fwd = np.array([math.cos(heading), math.sin(heading), 0.0])
    off = width_m / 2 + HAND_FACE_OFFSET_M + gap_m
    base = np.asarray(center_w, dtype=float) + np.array([0.0, 0.0, dz_m]) + ahead_m * fwd
    return base + off * lateral, base - off * lateral


def hand_forces(heading: float, squeeze_n: float, weight_n: float) -> np.ndarray:
    """(2, 3): what a box squeezed with squeeze_n per hand and weighing weight_n does to the hands."""
    lateral = np.array([-math.sin(heading), math.cos(heading), 0.0])
    down = np.array([0.0, 0.0, -weight_n / 2])
    return np.array([squeeze_n * lateral + down, -squeeze_n * lateral + down])


__all__ = [
    "GRASP_DISTANCE_M",
    "Approach",
    "approach_for",
    "grasp_width",
    "hand_forces",
    "hand_points",
    "pick_approach",
    "place_target",
]
