"""GoalGenerator's dispatch and hand-over, driven kinematically (no physics: while walking the base
moves as commanded, in whole-body phases the robot is where the plan says): goals the robot
cannot do fail with their reason and the next goal still runs; without a world pose every goal
fails saying so; after setting a box down the robot is back with the walking policy when the
goal is reported reached; a reach holds its pose under the whole-body controller until a walking
command hands back."""

from __future__ import annotations

import math
import time

import numpy as np

from g1_control.generator.goals.executor import FAILED, REACHED, GoalConfig, GoalGenerator
from g1_control.interfaces import Generator
from g1_control.robot import g1
from g1_control.rotations import yaw_of
from g1_control.scene import Box, SceneConfig, Table
from g1_control.types import PHASE_LOCOMOTION, PHASE_WHOLE_BODY, Command, KinematicReference, RobotState, TaskGoal

DT = 0.01


class Walking(Generator):
    """The walking side's generator: records the command it was given (the approach's walk)."""

    def __init__(self) -> None:
        self.command = Command()

    def update(self, command: Command, state: RobotState) -> KinematicReference:
        self.command = command
        return KinematicReference()


def _state(xy=(0.0, 0.0), yaw=0.0, world_pose=True) -> RobotState:
    return RobotState(q_rad=g1.DEFAULT_Q_RAD.copy(), imu_quat_wxyz=np.array([math.cos(yaw / 2), 0, 0, math.sin(yaw / 2)]),
                      base_pos_w_m=np.array([xy[0], xy[1], 0.79]) if world_pose else None,
                      base_linvel_w_mps=np.zeros(3))


def _tick(gen: GoalGenerator, inner: Walking, state: RobotState, command: Command) -> None:
    gen.update(command, state)
    if gen.phase == PHASE_WHOLE_BODY:  # the robot is where the plan is
        j = gen.joint_reference(state.t_s)
        state.q_rad, state.imu_quat_wxyz = j.q_rad.copy(), j.root_quat_wxyz.copy()
        state.base_pos_w_m = j.root_pos_w_m.copy()
        state.base_linvel_w_mps = np.zeros(3)
    elif state.base_pos_w_m is not None:  # walking: the base moves as commanded (a goal's approach: its walker's)
        c = Command(*(float(v) for v in gen.ctx.walk)) if gen.walking_to_goal else inner.command
        yaw = yaw_of(state.imu_quat_wxyz)
        v = np.array([math.cos(yaw) * c.vx_mps - math.sin(yaw) * c.vy_mps,
                      math.sin(yaw) * c.vx_mps + math.cos(yaw) * c.vy_mps, 0.0])
        state.base_pos_w_m = state.base_pos_w_m + v * DT
        state.base_linvel_w_mps = v
        yaw += c.wz_radps * DT
        state.imu_quat_wxyz = np.array([math.cos(yaw / 2), 0, 0, math.sin(yaw / 2)])
        state.q_rad = g1.DEFAULT_Q_RAD.copy()


def _scene() -> SceneConfig:
    table = Table("table", (1.2, 0.0), (0.5, 0.8), 0.7)
    return SceneConfig(tables=[table], boxes=[Box("box", (1.1, 0.0), stands_on="table")])


def test_goals_that_cannot_be_done_fail_with_their_reason_and_the_next_goal_still_runs():
    inner = Walking()
    gen = GoalGenerator(inner, _scene(), GoalConfig())
    state = _state()
    goals = [TaskGoal("place", goal_id="place"), TaskGoal("step_down", goal_id="down"),
             TaskGoal("step_up", goal_id="up", target="table"), TaskGoal("pick", goal_id="ghost", object="ghost"),
             TaskGoal("reach", goal_id="reach", hand="right", offset_h_m=np.array([0.15, 0.0, 0.1]))]
    for k in range(int(10.0 / DT)):
        state.t_s = k * DT
        _tick(gen, inner, state, Command(tasks=goals))
        if "reach" in gen.goal_status:
            break
    assert gen.goal_status == {"place": FAILED, "down": FAILED, "up": FAILED, "ghost": FAILED, "reach": REACHED}
    assert gen.goal_messages == {"place": "holding no box", "down": "not standing on a platform",
                                 "up": "'table' is not a platform of the scene",
                                 "ghost": "'ghost' is not a box of the scene"}
    info = gen.goal_info["reach"]
    assert info["status"] == REACHED and info["hand"] == "right" and info["end_s"] > info["start_s"]


def test_without_a_world_pose_a_goal_fails_saying_so_and_the_robot_keeps_walking():
    inner = Walking()
    gen = GoalGenerator(inner, _scene(), GoalConfig())
    state = _state(world_pose=False)
    for k in range(10):
        state.t_s = k * DT
        ref = gen.update(Command(vx_mps=0.3, tasks=[TaskGoal("pick", goal_id="p", object="box")]), state)
    assert gen.goal_status == {"p": FAILED}
    assert gen.goal_messages["p"].startswith("no world pose for the robot: a pick finds its box in the scene, which needs")
    assert gen.goal_messages["p"].endswith("nothing moved for this goal")
    assert gen.phase == PHASE_LOCOMOTION and ref.phase == PHASE_LOCOMOTION
    assert inner.command.vx_mps == 0.3  # the operator's command goes to the walking generator


def test_a_reach_holds_under_the_whole_body_controller_until_a_walking_command_hands_back():
    inner = Walking()
    gen = GoalGenerator(inner, _scene(), GoalConfig())
    state = _state()
    reach = TaskGoal("reach", goal_id="r", hand="left", offset_h_m=np.array([0.1, 0.05, 0.1]))
    k = 0
    while "r" not in gen.goal_status:
        state.t_s = k * DT
        _tick(gen, inner, state, Command(tasks=[reach]))
        k += 1
    for _ in range(int(3.0 / DT)):  # standing: the reach holds
        state.t_s = k * DT
        _tick(gen, inner, state, Command(tasks=[reach]))
        k += 1
    assert gen.goal_status == {"r": REACHED} and gen.phase == PHASE_WHOLE_BODY
    for _ in range(int(5.0 / DT)):  # a walking command: stand up, then hand back
        state.t_s = k * DT
        _tick(gen, inner, state, Command(vx_mps=0.2, tasks=[reach]))
        k += 1
        if gen.phase == PHASE_LOCOMOTION:
            break
    assert gen.phase == PHASE_LOCOMOTION and not gen.busy
    assert gen.log[-1][1] == "hand back to the walking policy"
    # the hand-back ends in the default arms
    arms = np.array(g1.ARM_JOINTS)
    np.testing.assert_allclose(gen.joint_reference(state.t_s).q_rad[arms], g1.DEFAULT_Q_RAD[arms], atol=1e-4)


def _pick_and_place(config: GoalConfig) -> tuple[GoalGenerator, dict]:
    """A pick from the table and a place back on it, driven kinematically; (the generator, the phase
    each goal was reached in)."""
    inner = Walking()
    gen = GoalGenerator(inner, _scene(), config)
    state = _state(xy=(0.0, 0.0))
    goals = [TaskGoal("pick", goal_id="pick", object="box"), TaskGoal("place", goal_id="place", object="box",
                                                                      target="table")]
    phase_when_reached: dict = {}
    deadline = time.monotonic() + 300.0  # planning beside the ticks: the plans' wall time, not the ticks', bounds it
    k = 0
    while time.monotonic() < deadline:
        state.t_s = k * DT
        _tick(gen, inner, state, Command(tasks=goals[:1] if "pick" not in gen.goal_status else goals))
        for gid in gen.goal_status:
            phase_when_reached.setdefault(gid, gen.phase)
        if "place" in gen.goal_status:
            break
        if gen.ctx.planner is not None:
            time.sleep(0.002)  # a loop's tick takes time: the planner's process gets the CPU
        k += 1
    return gen, phase_when_reached


def test_after_setting_a_box_down_the_walking_policy_has_the_robot_when_the_goal_is_reached():
    gen, phase_when_reached = _pick_and_place(GoalConfig())
    assert gen.goal_status == {"pick": REACHED, "place": REACHED}, gen.goal_messages
    # held after the pick (whole body), handed back to the walking policy once set down
    assert phase_when_reached == {"pick": PHASE_WHOLE_BODY, "place": PHASE_LOCOMOTION}
    assert gen.holding is None and gen.box_positions["box"] is not None
    assert "hand back to the walking policy" in [text for _, text in gen.log]


def test_a_pick_and_place_planned_in_the_planner_process_are_the_ones_planned_inline():
    # the stance search, the grasp and the release run as jobs in the real planner process (pickled
    # there and back): the same stances and the box set down where the inline plans put it
    inline, _ = _pick_and_place(GoalConfig())
    there, phases = _pick_and_place(GoalConfig(plan_in_background=True))
    try:
        assert there.goal_status == {"pick": REACHED, "place": REACHED}, there.goal_messages
        assert phases == {"pick": PHASE_WHOLE_BODY, "place": PHASE_LOCOMOTION}
        planned = {key for key in there.plan_cpu_s if key.endswith("(planner process, wall)")}
        assert {"pick stance (planner process, wall)", "pick grasp (planner process, wall)",
                "place stance (planner process, wall)", "place release (planner process, wall)"} <= planned
        assert not any(key.endswith(("stance", "grasp", "release")) for key in there.plan_cpu_s)  # none inline
        for goal in ("pick", "place"):
            assert there.goal_info[goal]["stance"] == inline.goal_info[goal]["stance"]
        np.testing.assert_allclose(there.box_positions["box"], inline.box_positions["box"], atol=1e-9)
    finally:
        there.ctx.close()
