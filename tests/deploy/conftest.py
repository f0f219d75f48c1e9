"""Fixtures of the deploy tests (helpers live in deploy_test_helpers.py)."""

from __future__ import annotations

import pytest
from deploy_test_helpers import new_partition


@pytest.fixture
def partition() -> str:
    return new_partition()


@pytest.fixture
def mock_robot(partition):
    """A robot emulator (MockG1 motors, built-in controller active) on lo, domain 1, in this process."""
    from g1_control.sim.emulator import RobotEmulator
    from g1_control.sim.mock_robot import MockG1

    made = []

    def make(**mock_kwargs):
        emulator = RobotEmulator(MockG1(**mock_kwargs), "lo", 1, partition=partition)
        made.append(emulator)
        return emulator

    yield make
    for emulator in made:
        emulator.close()
