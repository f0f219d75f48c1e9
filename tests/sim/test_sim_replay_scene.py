"""ReplayScene: what a replay draws besides the robot, its trajectory-file form and its poses in time."""

import json

import mujoco
import numpy as np

from g1_control.sim.replay_scene import ReplayScene, replay_model

SCENE = {"platforms": [{"name": "step", "center_xy_m": [1.5, 0.0], "size_xy_m": [0.7, 1.2], "height_m": 0.15}],
         "tables": [{"name": "table", "center_xy_m": [0.0, 2.0], "size_xy_m": [0.5, 0.8], "height_m": 0.7}],
         "boxes": [{"name": "box", "stands_on": "table", "xy_m": [0.0, 2.0], "size_m": [0.3, 0.3, 0.3]}]}


def _scene() -> ReplayScene:
    t = np.array([0.0, 1.0, 2.0])
    poses = np.array([[0.0, 2.0, 0.85, 1, 0, 0, 0], [0.5, 1.0, 0.9, 1, 0, 0, 0], [1.0, 0.0, 0.9, 1, 0, 0, 0]])
    cube = np.array([[x, y, z] for x in (-0.1, 0.1) for y in (-0.1, 0.1) for z in (-0.1, 0.1)])
    return ReplayScene(scene_json=json.dumps(SCENE), shapes_w_m={"rock": cube + [3.0, 0.0, 0.1]},
                       movers_m={"ball": cube}, object_t_s=t,
                       object_poses={"box": poses, "ball": poses + [0, 0, 1, 0, 0, 0, 0]})


def test_arrays_round_trip():
    scene = _scene()
    again = ReplayScene.from_arrays(scene.arrays())
    assert again.scene_json == scene.scene_json and set(again.object_poses) == {"box", "ball"}
    np.testing.assert_array_equal(again.shapes_w_m["rock"], scene.shapes_w_m["rock"])
    np.testing.assert_array_equal(again.object_t_s, scene.object_t_s)
    assert ReplayScene().empty and not again.empty and ReplayScene().arrays() == {}


def test_model_holds_the_scene_and_poses_follow_the_recorded_times():
    scene = _scene()
    model = replay_model(scene)
    data = mujoco.MjData(model)
    assert {model.geom("step").id, model.geom("table_top").id, model.geom("shape_rock").id} and model.nq == 36 + 14
    for t_s, row in ((0.0, 0), (0.99, 0), (1.0, 1), (1.7, 1), (5.0, 2), (-1.0, 0)):  # the last pose at or before
        scene.pose(model, data, t_s)
        mujoco.mj_kinematics(model, data)
        np.testing.assert_allclose(data.xpos[model.body("box").id], scene.object_poses["box"][row, :3])
        np.testing.assert_allclose(data.xpos[model.body("ball").id], scene.object_poses["ball"][row, :3])
    # drawn only: nothing added collides
    added = [g for g in range(model.ngeom) if model.geom_bodyid[g] == model.body("ball").id]
    assert added and all(model.geom_contype[g] == 0 and model.geom_conaffinity[g] == 0 for g in added)
