"""A scene in MuJoCo: objects where the launch file puts them, the robot read through its own
addresses, platforms counted as ground, hand collision boxes present."""

import pytest

from g1_control.robot import g1
from g1_control.scene import Box, Platform, SceneConfig, Table
from g1_control.sim.mujoco_backend import MujocoBackend


@pytest.fixture(scope="module")
def sim():
    scene = SceneConfig(tables=[Table("table_a", (1.5, 0.0), (0.5, 0.8), 0.7)],
                        platforms=[Platform("step", (0.0, 1.5), (0.6, 1.0), 0.15)],
                        boxes=[Box("box", (1.4, 0.0), stands_on="table_a", mass_kg=2.0)])
    scene.validate("scene")
    return MujocoBackend(scene=scene)


def test_the_robot_state_is_unaffected_by_free_boxes(sim):
    state = sim.reset()
    assert state.q_rad.shape == (g1.NUM_JOINTS,)
    assert state.q_rad == pytest.approx(g1.DEFAULT_Q_RAD)
    assert state.base_pos_w_m[:2] == pytest.approx([0.0, 0.0]) and 0.7 < state.base_pos_w_m[2] < 0.8


def test_the_box_rests_on_its_table(sim):
    sim.reset()
    for _ in range(250):
        sim.step(0.002)
    pos, quat = sim.object_pose("box")
    assert pos == pytest.approx([1.4, 0.0, 0.85], abs=3e-3)
    assert abs(quat[0]) == pytest.approx(1.0, abs=1e-3)


def test_grip_physics_and_hand_collision_are_in_the_model(sim):
    import mujoco

    assert sim.model.opt.cone == mujoco.mjtCone.mjCONE_ELLIPTIC and sim.model.opt.impratio == 100.0
    for side in ("left", "right"):
        assert sim.model.geom(f"{side}_rubber_hand_collision").conaffinity == 1


def test_platforms_are_ground_and_tables_are_not(sim):
    m = sim.model
    step = m.geom("step").id
    assert m.geom_bodyid[step] == 0 and step in sim._ground_geoms  # a knee on a platform is a fall
    assert m.geom_bodyid[m.geom("table_a_top").id] != 0  # a hand may touch a table
