"""A pick grips a box where the place queued right after it will set it down from (handling.place_grip_m): a
tall box going to the floor or a low table is taken higher than at its centre, so that the place (which sets
the box down from where the pick took it, context.Held.hand_dz_m) reaches its rest; no place next, another
box's place, a place whose height is not known before the carry, or a box of PLACE_GRIP_MAX_KG or more: no
look-ahead."""

from collections import deque

import numpy as np
import pytest

from g1_control.generator.goals.context import GoalConfig, GoalContext
from g1_control.generator.goals.handling import PLACE_GRIP_MAX_KG, place_grip_m
from g1_control.generator.goals.stances import hand_height
from g1_control.scene import Box, SceneConfig, Table
from g1_control.types import TaskGoal


@pytest.fixture(scope="module")
def ctx_box():
    tall = Box("box", (1.0, 0.0), stands_on="high", size_m=(0.2, 0.2, 0.44), mass_kg=1.0)
    other = Box("other", (1.0, 0.5), stands_on="high", size_m=(0.2, 0.2, 0.44), mass_kg=1.0)
    scene = SceneConfig(tables=[Table("high", (1.2, 0.2), (0.5, 1.2), 0.8), Table("low", (0.0, 1.5), (0.5, 0.8), 0.25)],
                        boxes=[tall, other])
    return GoalContext(scene, GoalConfig()), tall


def _grip(ctx_box, *goals):
    ctx, box = ctx_box
    ctx.queued = deque(goals)
    return place_grip_m(ctx, box)


def test_the_place_queued_next_sets_the_grip(ctx_box):
    _, box = ctx_box
    floor = _grip(ctx_box, TaskGoal("place", "p", object="box", pos_w_m=np.array([0.5, -1.0, 0.0])))
    assert floor == pytest.approx(hand_height(box, 0.22)) and floor > 0.05  # the floor: well above the centre
    low = _grip(ctx_box, TaskGoal("place", "p", target="low"))
    assert low == pytest.approx(hand_height(box, 0.25 + 0.22)) and low > 0.05
    assert _grip(ctx_box, TaskGoal("place", "p", target="high")) == 0.0  # high: at the centre, as a pick there


def test_no_look_ahead_without_a_known_place_of_this_box_next(ctx_box):
    assert _grip(ctx_box) is None
    assert _grip(ctx_box, TaskGoal("place", "p", object="other", target="low")) is None
    assert _grip(ctx_box, TaskGoal("reach", "r"), TaskGoal("place", "p", target="low")) is None
    assert _grip(ctx_box, TaskGoal("place", "p")) is None  # "put it down in front": where, the carry decides


def test_no_look_ahead_for_a_heavy_box():
    heavy = Box("box", (1.0, 0.0), stands_on="high", size_m=(0.2, 0.2, 0.44), mass_kg=PLACE_GRIP_MAX_KG)
    scene = SceneConfig(tables=[Table("high", (1.2, 0.2), (0.5, 1.2), 0.8)], boxes=[heavy])
    ctx = GoalContext(scene, GoalConfig())
    ctx.queued = deque([TaskGoal("place", "p", pos_w_m=np.array([0.5, -1.0, 0.0]))])
    assert place_grip_m(ctx, heavy) is None
