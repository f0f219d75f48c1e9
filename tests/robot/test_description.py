"""The pinocchio and MuJoCo models are built from one URDF and must agree."""

import mujoco
import numpy as np
import pinocchio as pin

from g1_control.robot import description, g1


def test_models_have_the_g1_joints_in_order():
    mj = description.mujoco_model()
    assert [mj.joint(i).name for i in range(1, mj.njnt)] == list(g1.JOINT_NAMES)
    assert [mj.actuator(i).name + "_joint" for i in range(mj.nu)] == list(g1.JOINT_NAMES)
    np.testing.assert_allclose(mj.dof_armature[6:], g1.ARMATURE_KGM2)
    np.testing.assert_allclose(mj.actuator_ctrlrange[:, 1], g1.EFFORT_LIMIT_NM)
    pm = description.pinocchio_model()
    assert (pm.nq, pm.nv) == (36, 35)
    assert abs(pin.computeTotalMass(pm) - mj.body_subtreemass[1]) < 1e-6


def test_forward_kinematics_agree():
    rng = np.random.default_rng(0)
    mj = description.mujoco_model()
    data = mujoco.MjData(mj)
    pm = description.pinocchio_model()
    pd = pm.createData()
    bodies = ["left_ankle_roll_link", "right_ankle_roll_link", "left_wrist_yaw_link",
              "right_wrist_yaw_link", "torso_link", "left_knee_link"]
    worst = 0.0
    for _ in range(20):
        q = rng.uniform(g1.Q_MIN_RAD, g1.Q_MAX_RAD)
        quat = rng.normal(size=4)
        quat /= np.linalg.norm(quat)
        pos = rng.normal(size=3)
        data.qpos[:] = np.concatenate([pos, quat, q])
        mujoco.mj_kinematics(mj, data)
        pin.framesForwardKinematics(pm, pd, description.pinocchio_q(pos, quat, q))
        for body in bodies:
            fid = pm.getFrameId(body)
            worst = max(worst, np.abs(pd.oMf[fid].translation - data.body(body).xpos).max())
            np.testing.assert_allclose(pd.oMf[fid].rotation, data.body(body).xmat.reshape(3, 3), atol=1e-6)
    assert worst < 1e-6



def test_hard_joint_stops_hold_a_joint_pressed_by_its_motor_at_full_torque_at_its_stop():
    """The G1's stops are metal: a joint pressed into one at its motor's effort limit rests at it, not
    0.126 rad past it (a wrist roll under 25 N m with MuJoCo's default soft limits)."""
    for timestep_s in (0.002, 0.005):  # the robot's physics step, and unitree_mujoco's
        model = description.mujoco_spec(timestep_s=timestep_s, hard_stops=True).compile()
        data = mujoco.MjData(model)
        for side, stop in ((1.0, g1.Q_MAX_RAD), (-1.0, g1.Q_MIN_RAD)):
            mujoco.mj_resetData(model, data)
            data.qpos[2] = 2.0  # the pelvis held in the air: no foot reaches the floor
            data.qpos[7:] = stop  # every joint at its stop, at rest
            base = data.qpos[:7].copy()
            data.qfrc_applied[6:] = side * g1.EFFORT_LIMIT_NM
            for _ in range(round(1.0 / timestep_s)):
                data.qpos[:7], data.qvel[:6] = base, 0.0
                mujoco.mj_step(model, data)
            past = side * (data.qpos[7:] - stop)
            worst = int(np.argmax(past))
            assert past[worst] < 0.002, (f"{timestep_s} s steps: {g1.JOINT_NAMES[worst]} rests {past[worst]:.4f} rad "
                                         f"past its stop under {g1.EFFORT_LIMIT_NM[worst]:.0f} N m")
