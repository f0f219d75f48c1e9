"""The simulator builds the G1 variant it is asked for (MujocoConfig.variant, a launch file's
backend.expected_variant): the joints the variant lacks are not in the model, one motor per joint it
has, and its state reads like the robot's LowState_ (mode_machine; 0 in the slots without a motor)."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from g1_control.errors import RobotDescriptionError
from g1_control.robot import g1
from g1_control.sim.mujoco_backend import MujocoBackend, MujocoConfig
from g1_control.types import MotorCommand

DROPPED_23 = ("waist_roll_joint", "waist_pitch_joint", "left_wrist_pitch_joint", "left_wrist_yaw_joint",
              "right_wrist_pitch_joint", "right_wrist_yaw_joint")


@pytest.mark.parametrize(("variant", "nu", "mode_machine"),
                         [("g1_29dof", 29, 5), ("g1_23dof", 23, 4), ("g1_29dof_locked_waist", 27, 6)])
def test_the_model_has_one_motor_per_joint_of_the_variant(variant, nu, mode_machine):
    backend = MujocoBackend(MujocoConfig(variant=variant))
    m = backend.model
    assert m.nu == nu and m.nq == 7 + nu and m.nv == 6 + nu
    motors = [m.joint(int(m.actuator_trnid[a, 0])).name for a in range(m.nu)]
    assert motors == [g1.JOINT_NAMES[i] for i in g1.variant_named(variant).active_joints]
    assert backend.reset().mode_machine == mode_machine


def test_the_23dof_model_lacks_waist_roll_pitch_and_wrist_pitch_yaw_but_keeps_their_links():
    m = MujocoBackend(MujocoConfig(variant="g1_23dof")).model
    joints = {m.joint(j).name for j in range(m.njnt)}
    assert not joints & set(DROPPED_23)
    full = MujocoBackend().model
    # the links are still there (welded to their parents): same bodies, same mass
    assert m.nbody == full.nbody
    assert np.sum(m.body_mass) == pytest.approx(np.sum(full.body_mass))


def test_the_23dof_state_reads_zero_where_there_is_no_motor_and_commands_there_do_nothing():
    def run(command_missing: bool) -> np.ndarray:
        backend = MujocoBackend(MujocoConfig(variant="g1_23dof"))
        backend.reset()
        cmd = MotorCommand(q_rad=g1.DEFAULT_Q_RAD.copy(), kp=g1.KP_DEFAULT.copy(), kd=g1.KD_DEFAULT.copy())
        if command_missing:  # a 29-DoF command pushing the joints the 23-DoF G1 lacks hard
            for name in DROPPED_23:
                cmd.q_rad[g1.JOINT_INDEX[name]] = 0.4
                cmd.tau_nm[g1.JOINT_INDEX[name]] = 5.0
        backend.write_command(cmd)
        backend.step(0.2)
        state = backend.read_state()
        dropped = [g1.JOINT_INDEX[n] for n in DROPPED_23]
        assert not state.q_rad[dropped].any() and not state.dq_radps[dropped].any() and not state.tau_nm[dropped].any()
        assert np.abs(state.tau_nm[list(g1.LEG_JOINTS)]).max() > 1.0, "the legs' motors carry the robot"
        return backend.data.qpos.copy()

    assert np.array_equal(run(False), run(True))


def test_the_23dof_motor_law_drives_the_joint_it_is_written_for():
    backend = MujocoBackend(MujocoConfig(variant="g1_23dof"))
    backend.reset()
    elbow = g1.JOINT_INDEX["right_elbow_joint"]
    cmd = MotorCommand(q_rad=g1.DEFAULT_Q_RAD.copy(), kp=g1.KP_DEFAULT.copy(), kd=g1.KD_DEFAULT.copy())
    cmd.q_rad[elbow] += 0.5
    backend.write_command(cmd)
    backend.step(0.5)
    q = backend.read_state().q_rad
    assert q[elbow] - g1.DEFAULT_Q_RAD[elbow] > 0.3
    adr = backend.model.jnt_qposadr[backend.model.joint("right_elbow_joint").id]
    assert backend.data.qpos[adr] == q[elbow]


def test_an_unknown_variant_is_refused_by_name():
    with pytest.raises(RobotDescriptionError, match=r"MujocoConfig.variant: unknown G1 variant 'g1_27dof'; known: "
                                                    r"g1_23dof, g1_29dof, g1_29dof_locked_waist"):
        MujocoBackend(MujocoConfig(variant="g1_27dof"))


def test_the_23dof_robot_stands_under_its_default_pd_for_a_moment():
    backend = MujocoBackend(MujocoConfig(variant="g1_23dof"))
    backend.reset()
    backend.step(0.3)
    assert backend.read_state().base_pos_w_m[2] > 0.7
    assert mujoco.mj_name2id(backend.model, mujoco.mjtObj.mjOBJ_ACTUATOR, "waist_roll") == -1


# -- backend.hands: dex3 ---------------------------------------------------------------------------------
def test_dex3_hands_are_built_with_their_fingers_held_open_and_a_motor_each_after_the_body_s_29():
    from g1_control.robot import description

    backend = MujocoBackend(MujocoConfig(hands="dex3"))
    m = backend.model
    fingers = description.finger_joint_names()
    assert len(fingers) == 14 and m.nu == 29 + 14 and m.njnt == 1 + 29 + 14
    assert [m.actuator(i).name for i in range(29)] == [n.removesuffix("_joint") for n in g1.JOINT_NAMES]
    assert sorted(m.actuator(i).name for i in range(29, 43)) == sorted(f.removesuffix("_joint") for f in fingers)
    assert np.sum(m.body_mass) == pytest.approx(34.394, abs=1e-3)  # the hand URDF's mass (rubber hands: 33.34)
    assert mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, "left_hand_palm_link") >= 0
    assert mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, "left_rubber_hand") == -1
    state = backend.reset()
    elbow = g1.JOINT_INDEX["left_elbow_joint"]
    cmd = MotorCommand(q_rad=g1.DEFAULT_Q_RAD.copy(), kp=g1.KP_DEFAULT.copy(), kd=g1.KD_DEFAULT.copy())
    cmd.q_rad[elbow] += 0.4
    backend.write_command(cmd)
    backend.step(0.5)
    state = backend.read_state()
    adr = m.jnt_qposadr[m.joint("left_elbow_joint").id]
    assert state.q_rad[elbow] == backend.data.qpos[adr] and state.q_rad[elbow] - g1.DEFAULT_Q_RAD[elbow] > 0.25
    finger_q = [backend.data.qpos[m.jnt_qposadr[m.joint(f).id]] for f in fingers]
    assert np.abs(finger_q).max() < 0.2, "the fingers hold the open pose against gravity and the arm's motion"


def test_dex3_hands_on_the_23dof_robot_are_refused():
    with pytest.raises(RobotDescriptionError, match="Dex3 hands are modelled on the 29-DoF G1 only, not on g1_23dof"):
        MujocoBackend(MujocoConfig(variant="g1_23dof", hands="dex3"))


def test_a_scene_with_dex3_hands_builds_without_the_rubber_hand_boxes():
    from g1_control.scene import Box, SceneConfig

    scene = SceneConfig(boxes=[Box(name="box", xy_m=(0.6, 0.0))])
    assert scene.hand_collision
    m = MujocoBackend(MujocoConfig(hands="dex3"), scene=scene).model
    geoms = {m.geom(i).name for i in range(m.ngeom)}
    assert "box_geom" in geoms and not any(name.endswith("rubber_hand_collision") for name in geoms)
    rubber = MujocoBackend(scene=scene).model
    assert "right_rubber_hand_collision" in {rubber.geom(i).name for i in range(rubber.ngeom)}


def test_sim_robot_refuses_a_mode_machine_it_cannot_build(capsys):
    from g1_control.cli.main import main

    assert main(["sim-robot", "--mode-machine", "9", "--seconds", "0.1", "--rt-priority", "0"]) == 1
    assert ("--mode-machine: unknown G1 mode_machine 9; known: 4 (g1_23dof), 5 (g1_29dof), 6 (g1_29dof_locked_waist)"
            in capsys.readouterr().err)
