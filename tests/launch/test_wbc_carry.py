"""The whole-body controller walks with a held box (tracker.type wbc in a scene): it picks a 3 kg box
from a table (the goal skills), then walks ~1 m from velocity commands while holding it. Judged from
MuJoCo's ground truth: the box stays between the hands, off the floor, and moves with the robot."""

import numpy as np

from g1_control.launch.builder import build_loop
from g1_control.launch.schema import load_launch, parse_launch
from g1_control.report.outcomes import GoalWatcher
from g1_control.trackers.wbc.tracker import WholeBodyTracker
from tests.paths import LAUNCH_DIR

PICK_S, WALK_S, STOP_S = 22.0, 5.0, 2.0


def carry_launch() -> dict:
    return {
        "name": "wbc_carry_test",
        "backend": {"type": "mujoco", "mode": "lockstep", "physics_dt_s": 0.002},
        "rates": {"lowlevel_hz": 500, "tracker_hz": 250, "input_hz": 100, "estimator_hz": 100},
        "tracker": {"type": "wbc"},
        "generator": {"type": "velocity"},
        "scene": {"tables": [{"name": "table", "center_xy_m": [0.95, 0.0], "size_xy_m": [0.5, 0.8], "height_m": 0.7}],
                  "boxes": [{"name": "box", "stands_on": "table", "xy_m": [0.85, 0.0], "size_m": [0.3, 0.3, 0.3],
                             "mass_kg": 3.0, "friction": 1.0}]},
        "input": {"type": "scripted", "timeline": [
            {"duration_s": PICK_S, "label": "pick", "goals": [{"kind": "pick", "object": "box"}]},
            {"duration_s": WALK_S, "vx_mps": -0.25, "label": "back with the box"},
            {"duration_s": STOP_S, "label": "stop"}]},
        "output": {"video": False, "plot": False},
    }


def test_walks_a_metre_with_a_held_box_and_keeps_it_in_the_hands():
    launch = parse_launch(carry_launch())
    assert launch.executes_goals
    loop = build_loop(launch)
    assert isinstance(loop.tracker, WholeBodyTracker) and loop.tracker.config.footsteps == "velocity"
    loop.reset()
    watcher = GoalWatcher(loop)
    loop.scheduler.run(round(launch.total_duration_s * loop.rates.lowlevel_hz), progress=watcher.tick)
    assert not loop.fell
    assert loop.generator.goal_status == {"seg0.0": "reached"}, loop.generator.goal_messages
    a = watcher.arrays()
    t, box, hands = a["t_s"], a["box_box"][:, :3], a["hands_w_m"]
    walk = (t >= PICK_S) & (t <= PICK_S + WALK_S + STOP_S)
    # ground truth: the box's centre stays between the hands (a dropped or rolled box leaves them)
    gap = np.linalg.norm(box[walk] - hands[walk].mean(axis=1), axis=1)
    assert gap.max() < 0.05, f"box {gap.max() * 100:.1f} cm from between the hands while walking"
    assert box[walk, 2].min() > 0.6, f"box down to {box[walk, 2].min():.2f} m"
    carried = float(np.hypot(*(box[walk][-1, :2] - box[walk][0, :2])))
    assert carried > 0.8, f"box carried {carried:.2f} m"
    assert loop.generator.holding == "box"


def test_the_carry_launch_walks_forward_with_its_3kg_box():
    """launch/sim_wbc_carry.yaml to 5 s into its forward walk (0.3 m/s, after the pick, the back-off and
    the turn): without the box's inertia in the controller's dynamics (WbcConfig.held_load_inertia) the
    DCM ran ahead and the robot fell 2.7 s into it (issue 23). Ground truth: no fall, the box between
    the hands, the pelvis ~1.5 m along."""
    launch = load_launch(LAUNCH_DIR / "sim_wbc_carry.yaml")
    walk_from = sum(seg.duration_s for seg in launch.input.timeline[:4])
    assert launch.input.timeline[4].vx_mps == 0.3
    loop = build_loop(launch)
    loop.reset()
    watcher = GoalWatcher(loop)
    rate = loop.rates.lowlevel_hz
    loop.scheduler.run(round(walk_from * rate), stop=lambda: loop.fell, progress=watcher.tick)
    start = loop.backend.data.qpos[:2].copy()
    loop.scheduler.run(round(5.0 * rate), stop=lambda: loop.fell, progress=watcher.tick)
    assert not loop.fell
    walked = float(np.linalg.norm(loop.backend.data.qpos[:2] - start))
    assert walked > 1.2, f"walked {walked:.2f} m in 5 s at 0.3 m/s"
    a = watcher.arrays()
    walk = a["t_s"] >= walk_from
    gap = np.linalg.norm(a["box_box"][walk, :3] - a["hands_w_m"][walk].mean(axis=1), axis=1)
    assert gap.max() < 0.05, f"box {gap.max() * 100:.1f} cm from between the hands while walking"
    assert loop.generator.holding == "box"
