"""Typed instructions (InstructedInput) over a stand-in operator device and loop."""

from g1_control.interfaces import LineInput
from g1_control.program.instructed import InstructedInput
from g1_control.types import Command
from tests.program.test_program_device import FakeLoop


class Operator(LineInput):
    """Stands in for the keyboard: lines to hand over, a command to report, begin_line recorded."""

    lost = False

    def __init__(self):
        self.lines, self.command, self.prompts = [], Command(), []

    def poll(self, now_s):
        return self.command

    def take_line(self):
        return self.lines.pop(0) if self.lines else None

    def begin_line(self, prompt):
        self.prompts.append(prompt)

    def close(self):
        pass


def make(confirm=False):
    said = []
    op, loop = Operator(), FakeLoop()
    device = InstructedInput(op, confirm=confirm, say=said.append)
    loop.connect(device)
    return device, op, loop, said


def run_for(device, loop, seconds, dt=0.01):
    for _ in range(round(seconds / dt)):
        loop.step(device.poll(loop.t), dt)


def test_a_typed_line_runs_as_a_program_until_done():
    device, op, loop, said = make()
    op.lines.append("walk forward 1 meter and turn left")
    run_for(device, loop, 15.0)
    assert said[0] == "1. walk forward 1 m\n2. turn left 90 deg"
    assert any("walk forward 1 m: completed" in s and "ground truth" in s for s in said)
    assert said[-1] == "program done" and device.active is None
    assert 0.95 < loop.x < 1.1


def test_operator_motion_cancels_the_program():
    device, op, loop, said = make()
    op.lines.append("walk forward 3 meters")
    run_for(device, loop, 1.0)
    assert device.active is not None and loop.x > 0.1
    op.command = Command(vx_mps=0.2)
    cmd = device.poll(loop.t)
    assert cmd.vx_mps == 0.2 and device.active is None
    assert "program cancelled by the operator" in said


def test_a_line_that_does_not_parse_moves_nothing():
    device, op, loop, said = make()
    op.lines.append("wlak forward 2 meters")
    run_for(device, loop, 1.0)
    assert device.active is None and loop.x == 0.0
    assert said[0].startswith("not understood: unknown word 'wlak'") and "walk" in said[0]


def test_on_a_robot_the_program_is_shown_and_runs_only_after_yes():
    device, op, loop, said = make(confirm=True)
    op.lines.append("walk forward 1 meter")
    run_for(device, loop, 1.0)
    assert device.active is None and device.pending is not None and loop.x == 0.0
    assert said[0] == "1. walk forward 1 m" and op.prompts == ["y/n> "]
    op.lines.append("no")
    run_for(device, loop, 0.5)
    assert device.pending is None and device.active is None and "not run" in said
    op.lines += ["walk forward 1 meter", "y"]
    run_for(device, loop, 1.0)
    assert device.active is not None and loop.x > 0.05
