"""GoalGenerator without a world pose (the robot path: RobotState.base_pos_w_m is None), driven
kinematically (the robot is where the plan says): a reach relative to the robot and a height run;
goals against the scene fail at their start, saying why, with nothing moved."""

from __future__ import annotations

import numpy as np
import pytest

from g1_control.generator.goals.executor import FAILED, REACHED, GoalGenerator, world_pose_needed
from g1_control.interfaces import Generator
from g1_control.robot import g1
from g1_control.scene import Box, Platform, SceneConfig, Table
from g1_control.types import PHASE_LOCOMOTION, PHASE_WHOLE_BODY, Command, KinematicReference, RobotState, TaskGoal

DT = 0.02
RIGHT_SHOULDER_PITCH = g1.JOINT_INDEX["right_shoulder_pitch_joint"]


class Standing(Generator):
    def update(self, command: Command, state: RobotState) -> KinematicReference:
        return KinematicReference(q_rad=g1.DEFAULT_Q_RAD.copy())


def _scene() -> SceneConfig:
    return SceneConfig(tables=[Table("table", (1.2, 0.0), (0.6, 0.8), 0.7)],
                       boxes=[Box("box", (1.0, 0.0), stands_on="table", size_m=(0.2, 0.3, 0.2))],
                       platforms=[Platform("platform", (0.0, -1.5), (1.2, 0.7), 0.15)])


def _drive(gen: GoalGenerator, commands, seconds: float) -> RobotState:
    """Tick `gen` with `commands(t)`; while it plans whole-body motion the robot follows the plan
    exactly. The state never carries a world pose."""
    state = RobotState(q_rad=g1.DEFAULT_Q_RAD.copy())
    for k in range(int(seconds / DT)):
        state.t_s = k * DT
        gen.update(commands(state.t_s), state)
        assert state.base_pos_w_m is None
        if gen.phase == PHASE_WHOLE_BODY:
            j = gen.joint_reference(state.t_s)
            state.q_rad, state.imu_quat_wxyz = j.q_rad.copy(), j.root_quat_wxyz.copy()
    return state


def test_a_reach_relative_to_the_robot_runs_without_a_world_pose():
    gen = GoalGenerator(Standing(), _scene())
    goal = TaskGoal("reach", goal_id="r", hand="right", offset_h_m=np.array([0.25, 0.0, 0.20]))
    state = _drive(gen, lambda t: Command(tasks=[goal]), 8.0)
    assert gen.goal_status == {"r": REACHED}, gen.goal_messages
    assert gen.goal_info["r"]["frame"] == "stance"
    # the arm left its default (the issue: shoulder pitch stayed at 0.20 rad throughout)
    assert state.q_rad[RIGHT_SHOULDER_PITCH] < g1.DEFAULT_Q_RAD[RIGHT_SHOULDER_PITCH] - 0.3
    # the hand where the goal put it: 25 cm ahead of and 20 cm above its standing point (the robot faces +x)
    j = gen.joint_reference(state.t_s)
    q = np.concatenate([j.root_pos_w_m, j.root_quat_wxyz[[1, 2, 3, 0]], j.q_rad])
    standing = q.copy()
    standing[7:] = g1.DEFAULT_Q_RAD
    reached = gen.poses.hand_point(q, 1) - gen.poses.hand_point(standing, 1)
    assert np.allclose(reached, [0.25, 0.0, 0.20], atol=0.03), reached


@pytest.mark.parametrize("goal", [
    TaskGoal("reach", goal_id="g", pos_w_m=np.array([0.4, -0.2, 1.0])),
    TaskGoal("pick", goal_id="g", object="box"),
    TaskGoal("place", goal_id="g"),
    TaskGoal("step_up", goal_id="g", target="platform"),
    TaskGoal("step_down", goal_id="g"),
])
def test_goals_against_the_scene_fail_at_their_start_saying_why_and_nothing_moves(goal):
    gen = GoalGenerator(Standing(), _scene())
    state = RobotState(q_rad=g1.DEFAULT_Q_RAD.copy())
    ref = gen.update(Command(tasks=[goal]), state)
    assert gen.goal_status == {"g": FAILED}
    message = gen.goal_messages["g"]
    assert message.startswith("no world pose for the robot: ") and "nothing moved" in message
    assert world_pose_needed(goal) in message
    assert gen.phase == PHASE_LOCOMOTION and not gen.busy
    assert np.array_equal(ref.q_rad, g1.DEFAULT_Q_RAD)  # the walking side's reference, untouched


def test_which_goals_need_a_world_pose():
    assert world_pose_needed(TaskGoal("reach", offset_h_m=np.zeros(3))) is None
    for kind in ("pick", "place", "step_up", "step_down"):
        assert "needs to know where the robot is" in world_pose_needed(TaskGoal(kind))
    assert "offset_h_m" in world_pose_needed(TaskGoal("reach", pos_w_m=np.zeros(3)))


def test_a_height_the_policy_cannot_hold_runs_without_a_world_pose():
    gen = GoalGenerator(Standing(), _scene())
    state = _drive(gen, lambda t: Command(pelvis_height_m=0.60), 5.0)
    assert gen.phase == PHASE_WHOLE_BODY
    j = gen.joint_reference(state.t_s)
    assert j.root_pos_w_m[2] == pytest.approx(0.60, abs=0.01)  # the soles on the floor under it
