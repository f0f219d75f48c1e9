"""A goal's approach walk goes through a velocity generator whatever the launch file's generator:
the closed-loop walk to a stance needs its commands followed at once (a planning generator's lag
made the robot sway around the stance until the goal timed out)."""

from __future__ import annotations

import numpy as np

from g1_control.generator.goals.executor import GoalGenerator
from g1_control.generator.velocity import VelocityReferenceGenerator
from g1_control.ik.retargeter import IKConfig
from g1_control.ik.stage import IKStage
from g1_control.interfaces import Generator
from g1_control.robot import g1
from g1_control.scene import Box, SceneConfig, Table
from g1_control.types import PHASE_LOCOMOTION, Command, KinematicReference, RobotState, TaskGoal

DT = 0.02


class Planner(Generator):
    """Stands for a planning generator: it walks at whatever it planned, here never the command."""

    def __init__(self):
        self.commands: list[Command] = []
        self.resets = 0

    def reset(self, state: RobotState) -> None:
        self.resets += 1

    def update(self, command: Command, state: RobotState) -> KinematicReference:
        self.commands.append(command)
        ref = KinematicReference(q_rad=g1.DEFAULT_Q_RAD.copy())
        ref.root_linvel_h_mps[:2] = (0.0, 0.6)  # a sidestep nobody asked for
        return ref


def _scene() -> SceneConfig:
    return SceneConfig(tables=[Table("table", (3.0, 0.0), (0.6, 0.8), 0.7)],
                       boxes=[Box("box", (2.9, 0.0), stands_on="table", size_m=(0.3, 0.3, 0.3))])


def _state(t: float) -> RobotState:
    return RobotState(t_s=t, q_rad=g1.DEFAULT_Q_RAD.copy(), base_pos_w_m=np.array([0.0, 0.0, 0.78]),
                      base_linvel_w_mps=np.zeros(3))


def test_the_approach_walk_follows_its_own_commands_and_the_planner_resumes_after():
    inner = Planner()
    gen = GoalGenerator(inner, _scene())
    retarget = IKStage(IKConfig(dt_s=DT))  # the loop's IK stage: the walker's plans pass through it
    operator = Command(vx_mps=0.3, style="wave")
    ref = gen.update(operator, _state(0.0))
    assert not gen.walking_to_goal and inner.commands[-1] is operator and ref.root_linvel_h_mps[1] == 0.6
    goal = TaskGoal("pick", goal_id="p", object="box")
    before = len(inner.commands)
    for k in range(1, 20):
        ref = gen.update(Command(tasks=[goal]), _state(k * DT))
        out = retarget.solve(ref, g1.DEFAULT_Q_RAD)
    assert gen.walking_to_goal and gen.phase == PHASE_LOCOMOTION
    assert len(inner.commands) == before, "the planner was asked to walk the goal's approach"
    walk = gen.ctx.walk
    assert walk[0] > 0.1  # 3 m from the table: walking towards it
    np.testing.assert_allclose(ref.root_linvel_h_mps[:2], walk[:2])
    np.testing.assert_allclose(out.root_linvel_h_mps[:2], walk[:2])  # the walker's own plan, not the planner's
    # the goal given up (its walk timed out): the operator's generator again, planning from where the robot is
    gen.config.walk_timeout_s = 0.1
    resets = inner.resets
    for k in range(20, 40):
        ref = gen.update(operator, _state(k * DT))
    assert gen.goal_status == {"p": "failed"} and "did not reach the stance" in gen.goal_messages["p"]
    assert not gen.walking_to_goal and inner.commands[-1] is operator and inner.resets == resets + 1
    assert ref.root_linvel_h_mps[1] == 0.6 and ref.feasible_plan is None  # the planner's, for the IK to solve


def test_a_velocity_generator_walks_the_approach_itself():
    inner = VelocityReferenceGenerator()
    gen = GoalGenerator(inner, _scene())
    assert gen.walker is inner
