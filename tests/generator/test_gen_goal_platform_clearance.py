"""GoalGenerator on a platform, driven kinematically (the robot is where the plan says, no physics):
after stepping down it steps back clear of the platform before handing back to the walking policy,
which turns in place knowing nothing of the platform (a sole 4 cm from the edge and a shin on its
top edge: program 20 of `g1 bench program` fell there)."""

from __future__ import annotations

import math

import numpy as np

from g1_control.generator.goals.box import Approach
from g1_control.generator.goals.executor import REACHED, GoalConfig, GoalGenerator
from g1_control.generator.goals.stepping import SOLE_HALF_LENGTH_M, Stance
from g1_control.interfaces import Generator
from g1_control.robot import g1
from g1_control.scene import Platform, SceneConfig
from g1_control.types import PHASE_LOCOMOTION, PHASE_WHOLE_BODY, Command, KinematicReference, RobotState, TaskGoal

DT = 0.01


class Standing(Generator):
    """The walking side's generator: nothing to plan (the robot stands where it is)."""

    def update(self, command: Command, state: RobotState) -> KinematicReference:
        return KinematicReference()


def _quat_z(yaw: float) -> np.ndarray:
    return np.array([math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2)])


def test_after_stepping_down_the_robot_steps_back_clear_of_the_platform_before_the_hand_back():
    platform = Platform("platform", (0.0, -1.0), (1.2, 0.7), 0.15)  # near edge at y = -0.65, facing +y
    cfg = GoalConfig()
    gen = GoalGenerator(Standing(), SceneConfig(platforms=[platform]), cfg)
    # standing where the approach walk would stop: 0.2 m short of the stance in front of the edge
    heading = -math.pi / 2
    stance_mid = np.array([0.0, -0.65 + SOLE_HALF_LENGTH_M + cfg.toe_gap_m])
    start = Approach(stance_mid, heading).pelvis_xy() + cfg.approach_offset_m * np.array([0.0, 1.0])
    state = RobotState(q_rad=g1.DEFAULT_Q_RAD.copy(), imu_quat_wxyz=_quat_z(heading),
                       base_pos_w_m=np.array([start[0], start[1], 0.79]), base_linvel_w_mps=np.zeros(3))
    goals = [TaskGoal("step_up", goal_id="up", target="platform"), TaskGoal("step_down", goal_id="down")]
    hand_back = None
    for k in range(int(60.0 / DT)):
        state.t_s = k * DT
        command = Command(tasks=goals[:1] if "up" not in gen.goal_status else goals)
        gen.update(command, state)
        if gen.phase == PHASE_WHOLE_BODY:  # the robot is where the plan is
            j = gen.joint_reference(state.t_s)
            state.q_rad, state.imu_quat_wxyz = j.q_rad.copy(), j.root_quat_wxyz.copy()
            state.base_pos_w_m = j.root_pos_w_m.copy()
        elif gen.goal_status.get("down") == REACHED:
            hand_back = np.concatenate([state.base_pos_w_m, state.imu_quat_wxyz[[1, 2, 3, 0]], state.q_rad])
            break
    assert gen.goal_status == {"up": REACHED, "down": REACHED}, gen.goal_messages
    assert hand_back is not None and gen.phase == PHASE_LOCOMOTION
    stance = Stance.of(gen.ik, hand_back)
    assert np.all(np.abs(stance.pos[:, 2]) < 0.01)  # both soles on the floor
    # the stance's middle clear of the platform (it came down 0.16 m from the edge)
    assert platform.distance_xy(stance.mid_xy) >= cfg.clear_of_platform_m - 0.01
    assert abs(math.remainder(stance.heading - heading, 2 * math.pi)) < 0.05
