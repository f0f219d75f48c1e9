"""scene.robot_start (g1_control/launch/start_pose.py): a launch file's room in a frame of its own, the
robot's start given in it; every position re-expressed in the start frame when the file is read."""

from __future__ import annotations

import math

import numpy as np
import pytest

from g1_control.errors import LaunchFileError
from g1_control.launch.schema import parse_launch
from g1_control.launch.start_pose import to_start_frame

# The robot stands at (1.5, -0.5) in the room, facing the room's +y. Hand-worked answers in its start
# frame (x ahead, y to its left): the room point (1.5, 1.5) is 2 m ahead -> (2, 0); (0.5, -0.5) is 1 m
# to its left -> (0, 1); a room yaw of 0 is -90 deg for the robot.
ROOM = {
    "name": "room",
    "backend": {"type": "mujoco", "mode": "lockstep", "physics_dt_s": 0.002},
    "rates": {"lowlevel_hz": 500, "tracker_hz": 100, "input_hz": 50, "estimator_hz": 100},
    "tracker": {"type": "layer", "policy": "holosoma_loco_ppo"},
    "generator": {"type": "velocity"},
    "scene": {
        "robot_start": {"xy_m": [1.5, -0.5], "yaw_rad": math.pi / 2},
        "tables": [{"name": "t", "center_xy_m": [1.5, 1.5], "size_xy_m": [0.5, 0.8], "height_m": 0.7}],
        "platforms": [{"name": "step", "center_xy_m": [0.5, -0.5], "size_xy_m": [0.4, 0.4], "height_m": 0.1,
                       "yaw_rad": math.pi / 2}],
        "boxes": [{"name": "box", "stands_on": "t", "xy_m": [1.5, 1.4], "size_m": [0.3, 0.3, 0.3]}],
    },
    "input": {"type": "scripted", "timeline": [
        {"duration_s": 2, "label": "stand"},
        {"duration_s": 10, "label": "reach", "goals": [{"kind": "reach", "hand": "right",
                                                         "pos_w_m": [1.8, 0.9, 1.0]}]}]},
}


def test_positions_given_in_the_rooms_frame_are_read_in_the_robots_start_frame():
    launch = parse_launch(ROOM)
    table, step, box = launch.scene.tables[0], launch.scene.platforms[0], launch.scene.boxes[0]
    assert list(table.center_xy_m) == pytest.approx([2.0, 0.0], abs=1e-9)
    assert table.yaw_rad == pytest.approx(-math.pi / 2)
    assert list(step.center_xy_m) == pytest.approx([0.0, 1.0], abs=1e-9) and step.yaw_rad == pytest.approx(0.0)
    assert list(box.xy_m) == pytest.approx([1.9, 0.0], abs=1e-9) and box.yaw_rad == pytest.approx(-math.pi / 2)
    goal = launch.input.timeline[1].goals[0]
    assert list(goal.pos_w_m) == pytest.approx([1.4, -0.3, 1.0], abs=1e-9)  # height unchanged
    assert ROOM["scene"]["robot_start"] == {"xy_m": [1.5, -0.5], "yaw_rad": math.pi / 2}, "the input is not changed"


def test_a_bottle_given_in_the_rooms_frame_is_read_in_the_robots_start_frame():
    scene = {**ROOM["scene"], "bottles": [{"name": "bottle", "stands_on": "t", "xy_m": [1.6, 1.5]}]}
    launch = parse_launch({**ROOM, "scene": scene})
    # (1.6, 1.5) in the room: 2 m ahead of the robot and 0.1 m to its right
    np.testing.assert_allclose(launch.scene.bottles[0].xy_m, (2.0, -0.1), atol=1e-9)


def test_the_robots_start_at_the_rooms_origin_changes_nothing():
    plain = {**ROOM, "scene": {k: v for k, v in ROOM["scene"].items() if k != "robot_start"}}
    assert to_start_frame(plain) is plain
    moved, kept = (parse_launch(d) for d in ({**ROOM, "scene": {**ROOM["scene"], "robot_start": {}}}, plain))
    assert repr(moved.scene) == repr(kept.scene)
    assert repr(moved.input.timeline) == repr(kept.input.timeline)


def test_program_places_and_a_scene_framed_external_pose_follow_the_start():
    data = {"name": "p", "scene": {"robot_start": {"xy_m": [1.0, 0.0], "yaw_rad": math.pi}},
            "input": {"type": "program", "places": {"door": {"pos_w_m": [-2.0, 0.0, 0.0], "kind": "point"}},
                      "program": [{"kind": "walk", "distance_m": 1.0}]},
            "estimation": {"external_pose": {"interface": "lo", "frame": "scene"}}}
    moved = to_start_frame(data)
    assert moved["input"]["places"]["door"]["pos_w_m"] == pytest.approx([3.0, 0.0, 0.0])  # 3 m ahead, facing -x
    assert moved["estimation"]["external_pose"]["start_in_scene"] == [1.0, 0.0, math.pi]


def test_a_scene_framed_external_pose_lands_in_the_start_frame():
    """Motion capture calibrated to the room: the robot seen at its start reads as the start frame's origin,
    and a pose 1 m further along the room's +y (the robot's heading) as 1 m ahead."""
    from g1_control.estimation.external_pose import ExternalPoseConfig, Planar, PoseFusion, PoseSample

    fusion = PoseFusion(ExternalPoseConfig(interface="lo", frame="scene", start_in_scene=[1.5, -0.5, math.pi / 2],
                                           correction_tau_s=1e-6, max_jump_m=2.0))
    for k in range(11):
        fusion.update(Planar(k * 0.01, 0.0, 0.0, 0.0))
    assert fusion.measure(PoseSample(0.1, 1.5, -0.5, math.pi / 2))
    assert fusion.fused is not None
    assert (fusion.fused.x_m, fusion.fused.y_m, fusion.fused.yaw_rad) == pytest.approx((0.0, 0.0, 0.0), abs=1e-6)
    fusion.update(Planar(0.2, 0.0, 0.0, 0.0))
    assert fusion.measure(PoseSample(0.2, 1.5, 0.5, math.pi / 2))
    assert (fusion.fused.x_m, fusion.fused.y_m) == pytest.approx((1.0, 0.0), abs=1e-3)


def test_the_simulator_builds_the_room_around_the_robots_start():
    """MuJoCo's world is the start frame: the box stands 1.9 m ahead of the robot, turned -90 deg."""
    from g1_control.rotations import yaw_of
    from g1_control.sim.mujoco_backend import MujocoBackend, MujocoConfig

    sim = MujocoBackend(MujocoConfig(lockstep=True), scene=parse_launch(ROOM).scene)
    try:
        pos, quat = sim.object_pose("box")
        assert pos[:2] == pytest.approx([1.9, 0.0], abs=1e-3) and pos[2] == pytest.approx(0.85, abs=0.01)
        assert abs(math.remainder(yaw_of(np.asarray(quat)) + math.pi / 2, math.pi / 2)) < 1e-3
    finally:
        sim.close()


def test_the_emulators_mocap_speaks_the_rooms_frame():
    from g1_control.estimation.external_pose import _scene_to_start
    from g1_control.rotations import yaw_of
    from g1_control.sim.emulator import _start_to_scene

    start = [1.5, -0.5, 1.0]
    pos, quat = _start_to_scene(start, np.array([2.0, 0.3, 0.7]), np.array([math.cos(0.2), 0.0, 0.0, math.sin(0.2)]))
    assert pos[2] == 0.7
    back = _scene_to_start(start).compose(pos[0], pos[1], yaw_of(quat))
    assert back == pytest.approx((2.0, 0.3, 0.4), abs=1e-9)


@pytest.mark.parametrize("start, message", [
    ([1.0, 2.0], "scene.robot_start: expected {xy_m: [x, y], yaw_rad: a}"),
    ({"xy_m": [1.0]}, "scene.robot_start.xy_m: expected 2 finite numbers, got [1.0]"),
    ({"xy_m": [1.0, math.nan]}, "scene.robot_start.xy_m: expected 2 finite numbers"),
    ({"xy_m": [1.0, 2.0, 0.5]}, "scene.robot_start.xy_m: expected 2 finite numbers, got [1.0, 2.0, 0.5]"),
    ({"yaw_rad": math.nan}, "scene.robot_start.yaw_rad: expected a finite number, got nan"),
    ({"yaw_rad": "north"}, "scene.robot_start.yaw_rad: expected a finite number, got 'north'"),
    ({"xy": [1.0, 2.0]}, "scene.robot_start: unknown key(s) xy; allowed: xy_m, yaw_rad"),
])
def test_a_bad_start_is_refused_naming_the_key(start, message):
    with pytest.raises(LaunchFileError) as err:
        parse_launch({**ROOM, "scene": {**ROOM["scene"], "robot_start": start}}, "room.yaml")
    assert str(err.value).startswith("room.yaml: " + message)


def test_a_table_on_the_robots_start_is_refused_after_the_move():
    """The clearance around the start is checked in the start frame: a table where the robot stands in the
    room is refused, though it is far from the room's origin."""
    scene = {"robot_start": {"xy_m": [3.0, 3.0]},
             "tables": [{"name": "t", "center_xy_m": [3.1, 3.0], "size_xy_m": [0.5, 0.5], "height_m": 0.7}]}
    with pytest.raises(LaunchFileError, match=r"scene.tables\[0\] \(t\): closer than 0.35 m to the robot's start"):
        parse_launch({**ROOM, "scene": scene, "input": {"type": "scripted", "timeline": [{"duration_s": 1}]}})
