"""Goal buttons: a press starts one task goal (pick the box in front, set it down, step up/down),
with a fresh id each time, on the gamepad, the Unitree remote and the keyboard."""

import pytest

from g1_control.errors import LaunchFileError
from g1_control.teleop.layouts import LAYOUTS
from g1_control.teleop.mapper import CommandMapper
from g1_control.teleop.mapping import MappingConfig
from g1_control.teleop.snapshot import InputSnapshot


@pytest.mark.parametrize("device, press, kind", [
    ("gamepad", "Y", "pick"), ("gamepad", "dpad_up", "step_up"), ("gamepad", "dpad_down", "step_down"),
    ("unitree_remote", "Y", "pick"), ("unitree_remote", "up", "step_up"),
    ("keyboard", "p", "pick"), ("keyboard", "l", "place"),
])
def test_a_goal_button_starts_one_goal_per_press(device, press, kind):
    mapper = CommandMapper(MappingConfig.default(device))
    held = frozenset() if device == "keyboard" else frozenset({press})
    first = mapper.update(InputSnapshot(held=held, pressed=(press,)), 0.0)
    assert [g.kind for g in first.tasks] == [kind]
    again = mapper.update(InputSnapshot(held=held), 0.02)  # still held: no new goal
    assert again.tasks == []
    mapper.update(InputSnapshot(), 0.04)
    second = mapper.update(InputSnapshot(held=held, pressed=(press,)), 0.06)
    assert second.tasks[0].goal_id != first.tasks[0].goal_id


def test_the_chord_places_and_the_single_button_does_not():
    mapper = CommandMapper(MappingConfig.default("gamepad"))
    cmd = mapper.update(InputSnapshot(held=frozenset({"LB", "Y"}), pressed=("LB", "Y")), 0.0)
    assert [g.kind for g in cmd.tasks] == ["place"]


def test_goal_actions_can_be_rebound_and_unknown_ones_are_refused():
    cfg = MappingConfig.from_dict({"buttons": {"A": "run", "X": "pick"}}, "input.device.mapping",
                                  layout=LAYOUTS["gamepad"])
    mapper = CommandMapper(cfg)
    assert mapper.update(InputSnapshot(held=frozenset({"X"}), pressed=("X",)), 0.0).tasks[0].kind == "pick"
    with pytest.raises(LaunchFileError, match="input.device.mapping.buttons.X is 'grab'"):
        MappingConfig.from_dict({"buttons": {"X": "grab"}}, "input.device.mapping", layout=LAYOUTS["gamepad"])
