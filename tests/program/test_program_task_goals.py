"""Behaviour programs drive the goal generator: reach/pick/place/step steps emit TaskGoals (same
ids as their GoalRequests, so the generator's goal_status completes the steps)."""

import numpy as np

from g1_control.program import Landmark, ProgramProgress, ProgramRunner, World, parse_instruction
from g1_control.types import TaskGoal


def _world():
    return World.of(Landmark("box", [2.0, 0.0, 0.85], "object"), Landmark("table", [2.2, 0.0, 0.7], "surface"),
                    Landmark("other_table", [1.0, 3.0, 0.7], "surface"), Landmark("platform", [0.0, 2.0, 0.15], "platform"))


def test_pick_and_place_steps_emit_task_goals_completed_by_their_status():
    runner = ProgramRunner(parse_instruction("pick up the box and put it on the other table"), _world())
    cmd = runner.update(0.0, ProgramProgress())
    (task,) = cmd.tasks
    assert isinstance(task, TaskGoal) and task.kind == "pick" and task.object == "box"
    assert task.goal_id == runner.active_goals[0].goal_id
    task.validate()
    cmd = runner.update(0.02, ProgramProgress(goal_status={task.goal_id: "reached"}))
    (place,) = cmd.tasks
    assert place.kind == "place" and place.target == "other_table" and place.object == "box"
    # on a table: by name only; the execution layer puts it where it can reach (the middle of the near
    # edge). The table's centre, passed as a point, was refused in MuJoCo as out of reach.
    assert place.pos_w_m is None
    runner.update(0.04, ProgramProgress(goal_status={task.goal_id: "reached", place.goal_id: "failed"}))
    assert [o.status for o in runner.outcomes] == ["completed", "failed"]


def test_reach_and_step_goals_map_onto_task_goals():
    runner = ProgramRunner(parse_instruction("step onto the platform"), _world())
    (task,) = runner.update(0.0, ProgramProgress()).tasks
    assert task.kind == "step_up" and task.target == "platform"
    runner = ProgramRunner(parse_instruction("reach forward with your left hand"), _world())
    (task,) = runner.update(0.0, ProgramProgress()).tasks
    task.validate()
    assert task.kind == "reach" and task.hand == "left" and (task.pos_w_m is not None or task.offset_h_m is not None)


def test_a_place_on_a_named_point_passes_the_point():
    world = World.of(Landmark("box", [2.0, 0.0, 0.85], "object"), Landmark("spot", [1.0, 1.0, 0.0], "point"))
    runner = ProgramRunner(parse_instruction("put the box on the spot", places=world.names()), world)
    (place,) = runner.update(0.0, ProgramProgress()).tasks
    assert place.target is None and np.allclose(place.pos_w_m, [1.0, 1.0, 0.0])
