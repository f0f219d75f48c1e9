"""The whole-body controller's own gait climbs a 0.15 m step it knows from the scene's map, in MuJoCo
(the full loop, safety included), approached at an angle: the lead foot lands with its whole sole on
the tread and both feet get up without a fall; walked on, it comes down the far side. Ground truth is
read for the checks only."""

import math

import mujoco
import numpy as np

from g1_control.launch.builder import build_loop
from g1_control.teleop.scripted import Segment
from g1_control.tools.bench_stairs import SOLE_BELOW_ANKLE_M, course_scene, draw
from g1_control.tools.physics_trials import Trial, trial_launch
from g1_control.trackers.wbc.terrain import Terrain

HEEL_BEHIND_ANKLE_M = 0.05
"""The heel's contact spheres sit this far behind the ankle-roll body's origin (the G1 model)."""


def test_a_015_m_step_approached_at_an_angle_is_climbed_with_the_whole_sole_on_the_tread():
    # seed 2 of `g1 bench stairs`: approached at -11.9 deg, 0.12 m off the axis; merged main
    # (1deb40c) fell before both feet were up (the knee on the step)
    angle_deg, offset_m = draw(2)
    scene, top_m, _ = course_scene("step", math.radians(angle_deg), offset_m)
    terrain = Terrain.of_scene(scene)
    trial = Trial("step_up", [Segment(1.0, label="stand"), Segment(11.0, vx_mps=0.3, label="walk")],
                  tracker="wbc", tracker_hz=250.0, scene=scene)
    loop = build_loop(trial_launch(trial))
    loop.reset()
    m, d = loop.backend.model, loop.backend.data  # type: ignore[attr-defined]
    feet = [mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, f"{side}_ankle_roll_link") for side in ("left", "right")]
    heels_on_tread = []
    prev = np.array([d.xpos[f].copy() for f in feet])
    try:
        while loop.time_s < 12.0:
            loop.run(0.02)
            assert not (loop.fell or loop.faulted), f"fell at {loop.time_s:.2f} s: {loop.fall}"
            on = []
            for i, f in enumerate(feet):
                sole_z = d.xpos[f][2] - SOLE_BELOW_ANKLE_M
                heel = d.xpos[f][:2] - HEEL_BEHIND_ANKLE_M * d.xmat[f].reshape(3, 3)[:2, 0]
                resting = float(np.linalg.norm(d.xpos[f] - prev[i])) < 0.002  # < 0.1 m/s over 0.02 s
                on.append(abs(sole_z - top_m) < 0.01)
                if on[-1] and resting:
                    heels_on_tread.append(terrain.height(heel))
                prev[i] = d.xpos[f]
            if all(on):
                break
        assert all(on), "both feet never got onto the step"
    finally:
        loop.backend.close()
    # every sole resting at the tread's height had its heel on the tread too (not straddling its edge)
    assert heels_on_tread and min(heels_on_tread) == top_m


def test_a_015_m_step_is_walked_up_and_down_without_a_fall():
    # seed 3 of `g1 bench stairs --only step`: approached at -20.7 deg, 0.16 m off the axis; main
    # fbb26fd fell stepping down off it (its knee struck the step's edge at 10.55 s: the foot landed
    # with its heel 0.1 m past the edge)
    from g1_control.tools.bench_stairs import run_course

    trial = run_course("step", 3, duration_s=16.0)
    assert trial.top and trial.across and not trial.fell, trial
