"""Walking with something held in a goal (approach.walk_holding; GoalConfig.walk_while_holding: the
whole-body controller's own gait): the reference the executor hands the tracker walks by the goal's
velocity (GoalContext.walk), not the operator's, holds the upper body at GoalContext.carry_q, and carries
a held bottle's weight on its hand with the moment turned to the robot's heading; back_off walks straight
back by the world pose and stops there, and refuses when the robot does not move."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest

from g1_control.generator.goals.approach import WALK_CLEAR_M, back_off, turn_walk_turn, walk_holding
from g1_control.generator.goals.bottle import held_wrench
from g1_control.generator.goals.box import Approach
from g1_control.generator.goals.context import GoalConfig, GoalFailed, HeldBottle
from g1_control.generator.goals.executor import GoalGenerator
from g1_control.generator.velocity import VelocityReferenceGenerator
from g1_control.robot import g1
from g1_control.rotations import wrap_angle
from g1_control.scene import Bottle, SceneConfig, Table
from g1_control.types import PHASE_LOCOMOTION, Command, RobotState, TaskGoal

DT_S = 0.01


def _quat(yaw: float) -> np.ndarray:
    return np.array([math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2)])


class Walker:
    """A GoalContext's view of a robot at `yaw` that moves as ctx.walk commands it (or not at all)."""

    def __init__(self, yaw: float, moves: bool = True):
        self.yaw, self.moves = yaw, moves
        self.xy = np.array([1.0, -2.0])
        self.walk = np.zeros(3)
        self.info: dict = {}
        self.t = 0.0
        self.config = GoalConfig(walk_timeout_s=5.0)
        self.commands: list[np.ndarray] = []

    def world_pose(self):
        return SimpleNamespace(imu_quat_wxyz=_quat(self.yaw)), np.array([*self.xy, 0.75])

    def step(self) -> None:
        self.commands.append(self.walk.copy())
        if self.moves:
            c, s = math.cos(self.yaw), math.sin(self.yaw)
            self.xy = self.xy + DT_S * np.array([c * self.walk[0] - s * self.walk[1], s * self.walk[0] + c * self.walk[1]])
        self.t += DT_S


def test_back_off_walks_straight_back_along_the_heading_until_it_has_gone_the_distance():
    robot = Walker(yaw=0.7)
    start = robot.xy.copy()
    for _ in back_off(robot, 0.3, speed_mps=0.2):  # type: ignore[arg-type]
        robot.step()
    moved = robot.xy - start
    heading = np.array([math.cos(0.7), math.sin(0.7)])
    assert float(moved @ heading) == pytest.approx(-0.3, abs=0.01)  # back, not forward
    assert abs(float(moved @ np.array([-heading[1], heading[0]]))) < 1e-9  # straight
    assert all(np.allclose(c, (-0.2, 0.0, 0.0)) for c in robot.commands)
    assert not robot.walk.any()  # it stops there


def test_back_off_refuses_when_the_robot_does_not_move():
    robot = Walker(yaw=0.0, moves=False)
    with pytest.raises(GoalFailed, match="did not back off 0.30 m"):
        for _ in back_off(robot, 0.3):  # type: ignore[arg-type]
            robot.step()
    assert robot.t == pytest.approx(robot.config.walk_timeout_s, abs=0.05)


def _generator() -> GoalGenerator:
    scene = SceneConfig(tables=[Table("table", (1.2, 0.0), (0.5, 0.8), 0.7)],
                        bottles=[Bottle("bottle", (1.1, 0.2), stands_on="table", mass_kg=0.6)])
    return GoalGenerator(VelocityReferenceGenerator(), scene, GoalConfig(walk_while_holding=True))


def _state(t: float, yaw: float) -> RobotState:
    return RobotState(t_s=t, q_rad=g1.DEFAULT_Q_RAD.copy(), imu_quat_wxyz=_quat(yaw),
                      base_pos_w_m=np.array([0.0, 0.0, 0.75]), base_linvel_w_mps=np.zeros(3))


def test_a_goals_walk_holding_a_bottle_walks_by_the_goals_velocity_with_the_arm_held_and_the_bottle_on_the_hand():
    gen = _generator()
    ctx = gen.ctx
    bottle = ctx.scene.bottles[0]
    pick_heading, yaw = 0.0, 1.1  # picked facing +x; the carry has turned the robot 1.1 rad
    ctx.held_bottle = HeldBottle(bottle, 1, 0.1, pick_heading, *held_wrench(bottle, 1, pick_heading))
    carry_q = g1.DEFAULT_Q_RAD.copy()
    carry_q[list(g1.ARM_JOINTS)] += 0.3
    ctx.carry_q = carry_q
    ctx.phase = PHASE_LOCOMOTION
    ctx.goal = TaskGoal(kind="place", object="bottle", goal_id="g")
    gen._coro = iter(())  # a goal is running (its coroutine is the walk)
    ctx.walk[:] = (0.3, 0.0, 0.0)
    operator = Command(vx_mps=0.0, vy_mps=0.4, wz_radps=-0.5)  # not what the goal's walk follows
    for k in range(150):
        ref = gen._reference(operator, _state(k * DT_S, yaw))
    assert ref.phase == PHASE_LOCOMOTION and ref.upper_body_override
    assert ref.root_linvel_h_mps[0] == pytest.approx(0.3, abs=0.02)
    assert abs(ref.root_linvel_h_mps[1]) < 1e-6 and abs(ref.root_angvel_h_radps[2]) < 1e-6
    j = gen.joint_reference(0.0)
    arms = list(g1.ARM_JOINTS)
    np.testing.assert_allclose(j.q_rad[arms], carry_q[arms])
    forces, moments = held_wrench(bottle, 1, yaw)  # as if picked facing where the robot now faces
    np.testing.assert_allclose(j.hand_forces_w_n, forces, atol=1e-9)
    np.testing.assert_allclose(j.hand_moments_w_nm, moments, atol=1e-9)
    assert np.abs(j.hand_forces_w_n[1]).max() > 5.0 and not j.hand_forces_w_n[0].any()


def test_between_goals_the_walk_holding_follows_the_operator():
    gen = _generator()
    ctx = gen.ctx
    ctx.carry_q = g1.DEFAULT_Q_RAD.copy()
    ctx.phase = PHASE_LOCOMOTION
    ctx.walk[:] = (0.3, 0.0, 0.0)  # a stale goal walk: not followed without a goal
    for k in range(150):
        ref = gen._reference(Command(vx_mps=0.0, vy_mps=0.2), _state(k * DT_S, 0.0))
    assert ref.root_linvel_h_mps[1] == pytest.approx(0.2, abs=0.02)
    assert abs(ref.root_linvel_h_mps[0]) < 1e-6
    assert not gen.joint_reference(0.0).hand_moments_w_nm.any()  # nothing held: no moments


class Omni(Walker):
    """Walker that also turns as commanded and reports its planar speed."""

    def world_pose(self):
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        v = np.array([c * self.walk[0] - s * self.walk[1], s * self.walk[0] + c * self.walk[1], 0.0])
        return SimpleNamespace(imu_quat_wxyz=_quat(self.yaw), base_linvel_w_mps=v), np.array([*self.xy, 0.75])

    def step(self) -> None:
        super().step()
        self.yaw += DT_S * self.walk[2]


@pytest.mark.parametrize("start_yaw", [0.0, 2.5, -2.0])
def test_turn_walk_turn_turns_walks_straight_then_turns_and_ends_facing_the_stance_at_its_point(start_yaw):
    robot = Omni(yaw=start_yaw)
    robot.config = GoalConfig(walk_timeout_s=60.0)
    approach = Approach(np.array([2.5, -0.4]), heading=-1.2)  # 1.6 m from the start, facing away from it
    for _ in turn_walk_turn(robot, approach, out_m=0.2):  # type: ignore[arg-type]
        robot.step()
    goal = approach.pelvis_xy() - 0.2 * np.array([math.cos(-1.2), math.sin(-1.2)])
    assert float(np.hypot(*(robot.xy - goal))) <= robot.config.approach_tolerance_m
    assert abs(wrap_angle(robot.yaw + 1.2)) <= robot.config.approach_heading_tolerance_rad / 2
    cmds = np.array(robot.commands)
    cfg = robot.config
    assert not cmds[:, 1].any(), "never sideways"
    assert cmds[:, 0].max() <= cfg.carry_walk_speed_mps + 1e-9 and cmds[:, 0].min() >= 0.0
    assert np.abs(cmds[:, 2]).max() <= cfg.carry_turn_rate_radps + 1e-9
    walking = cmds[:, 0] > 0
    assert np.abs(cmds[walking, 2]).max() <= cfg.carry_turn_rate_radps / 2 + 1e-9, "walking, it only steers"
    # one turn, one walk, one turn: the walk is a single stretch
    assert np.count_nonzero(np.diff(walking.astype(int)) == 1) == 1
    assert not cmds[-int(cfg.settle_s / DT_S):].any(), "it stood still to settle"


def test_walk_holding_stops_short_of_the_stance_only_where_that_point_is_clear_of_tables():
    """walk_holding backs off, then stops GoalConfig.approach_offset_m short of the stance, unless that
    point lies within WALK_CLEAR_M of a table: then nearer the stance (here at it: every point short of it
    is that near the table)."""
    approach = Approach(np.array([2.5, 0.0]), heading=0.0)
    table = Table("other", (2.1, -0.35), (0.4, 0.4), 0.7)
    assert table.distance_xy(approach.pelvis_xy() - np.array([0.2, 0.0])) < WALK_CLEAR_M
    ends = {}
    for name, tables in (("clear", []), ("table beside", [table])):
        robot = Omni(yaw=math.pi)
        robot.xy = np.array([1.0, 0.0])
        robot.config = GoalConfig(walk_timeout_s=60.0)
        robot.scene = SceneConfig(tables=tables)
        robot.carry_q, robot.phase, robot.plan = None, None, None
        for _ in walk_holding(robot, approach, g1.DEFAULT_Q_RAD, out_m=0.2, back_m=0.1):  # type: ignore[arg-type]
            robot.step()
        assert robot.carry_q is not None and robot.phase == PHASE_LOCOMOTION
        ends[name] = float(approach.pelvis_xy()[0] - robot.xy[0])  # how far short of the stance
    tolerance = GoalConfig().approach_tolerance_m
    assert 0.2 - tolerance <= ends["clear"] <= 0.2 + tolerance
    assert -tolerance <= ends["table beside"] <= tolerance


class Drifter(Omni):
    """Omni whose walk also slides sideways, `slip` m/s per m/s forward (a held load pulling it aside)."""

    slip = -0.6

    def step(self) -> None:
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        side = self.slip * self.walk[0]
        self.xy = self.xy + DT_S * side * np.array([-s, c])
        super().step()


def test_turn_walk_turn_faces_its_point_again_when_the_walk_cannot_steer_onto_it():
    """Walking, the robot steers at most carry_turn_rate_radps / 2: a point it slides past inside that
    turning circle it would circle until the walk's timeout (scene 145.0 on the tracking layer). Off its
    bearing by more than REFACE_RAD it turns on the spot to face the point again, and gets there."""
    from g1_control.generator.goals.approach import REFACE_RAD

    robot = Drifter(yaw=0.0)
    robot.config = GoalConfig(walk_timeout_s=60.0)
    approach = Approach(np.array([3.0, -2.0]), heading=0.0)
    for _ in turn_walk_turn(robot, approach, out_m=0.2):  # type: ignore[arg-type]
        robot.step()
    goal = approach.pelvis_xy() - np.array([0.2, 0.0])
    assert float(np.hypot(*(robot.xy - goal))) <= robot.config.approach_tolerance_m
    assert robot.t < 30.0
    cmds = np.array(robot.commands)
    walking = cmds[:, 0] > 0
    assert np.count_nonzero(np.diff(walking.astype(int)) == 1) >= 2, "it stopped walking to face the point again"
    assert 0.3 < REFACE_RAD < math.pi / 2
