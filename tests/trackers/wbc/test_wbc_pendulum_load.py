"""The held load the gait's pendulum walks with (tracker.pendulum_load_kg): a box in both hands counts,
its weight shared between them; a bottle in one hand does not (it stays in the QP's dynamics)."""

import numpy as np
import pytest

from g1_control.generator.goals.box import hand_forces
from g1_control.trackers.wbc.capture_point import GRAVITY_MPS2
from g1_control.trackers.wbc.tracker import pendulum_load_kg


def test_a_box_in_both_hands_is_in_the_pendulum_whatever_the_squeeze():
    forces = hand_forces(0.7, squeeze_n=25.0, weight_n=3.0 * GRAVITY_MPS2)  # as the goals send a held box
    assert pendulum_load_kg(forces) == pytest.approx(3.0)


@pytest.mark.parametrize("hand", [0, 1])
def test_a_load_in_one_hand_is_left_out_of_the_pendulum(hand):
    forces = np.zeros((2, 3))
    forces[hand, 2] = -0.64 * GRAVITY_MPS2  # a bottle (goals/bottle.py held_wrench)
    assert pendulum_load_kg(forces) == 0.0


def test_nothing_held_or_hands_pushed_up_is_no_load():
    assert pendulum_load_kg(np.zeros((2, 3))) == 0.0
    assert pendulum_load_kg(np.array([[0.0, 0.0, 5.0], [0.0, 0.0, 5.0]])) == 0.0
