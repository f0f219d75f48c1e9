"""Falls judged from ground truth (g1_control/safety/fall.py): the first of tilt, pelvis low, a body
other than the feet on the ground; checked on hand-built cases whose answer is known."""

import numpy as np
import pytest

from g1_control.errors import SafetyConfigError
from g1_control.estimation.estimator import StateEstimator
from g1_control.launch.builder import build_loop
from g1_control.launch.runner import run
from g1_control.launch.schema import LaunchFile, Segment
from g1_control.report.results import format_summary
from g1_control.safety.fall import FallConfig, FallMonitor
from g1_control.sim.mujoco_backend import MujocoBackend
from g1_control.types import MotorCommand

UPRIGHT = np.array([1.0, 0.0, 0.0, 0.0])


def test_monitor_reports_the_first_sign_and_latches_it():
    mon = FallMonitor(FallConfig(min_pelvis_height_m=0.4), max_tilt_rad=1.0)
    assert mon.update(0.0, UPRIGHT, 0.75, ()) is None
    fall = mon.update(1.0, UPRIGHT, 0.35, ("left_knee_link",))
    assert fall is not None and fall.kind == "pelvis_low" and fall.t_s == 1.0
    tilted = np.array([np.cos(0.6), np.sin(0.6), 0.0, 0.0])  # 1.2 rad about x
    assert mon.update(2.0, tilted, 0.2, ()) is None  # later signs do not replace the first
    assert mon.fall is fall


@pytest.mark.parametrize("height", [0.0, -0.1, 0.78, 0.9, float("nan")])
def test_a_fall_height_that_could_never_or_always_fire_is_refused(height):
    with pytest.raises(SafetyConfigError) as info:
        FallConfig(min_pelvis_height_m=height).validate("fall")
    assert str(info.value) == f"fall.min_pelvis_height_m is {height}; it must lie in (0, 0.78) m"
    FallConfig(min_pelvis_height_m=0.3).validate("fall")


def test_monitor_tilt_and_contacts():
    tilted = np.array([np.cos(0.6), np.sin(0.6), 0.0, 0.0])
    assert FallMonitor(max_tilt_rad=1.0).update(0.0, tilted, None, None).kind == "tilt"
    mon = FallMonitor(FallConfig(allowed_contacts=("left_wrist_yaw_link",)))
    assert mon.update(0.0, UPRIGHT, None, ("left_wrist_yaw_link",)) is None  # an allowed hand
    fall = mon.update(0.1, UPRIGHT, None, ("left_wrist_yaw_link", "right_knee_link"))
    assert fall.kind == "body_contact" and "right_knee_link" in fall.detail and "wrist" not in fall.detail


def test_mujoco_ground_contacts_are_feet_free_when_standing_and_name_the_knees_when_collapsed():
    backend = MujocoBackend()
    backend.reset()
    backend.step(0.2)
    assert backend.ground_contacts() == ()  # only the feet touch the floor
    backend.write_command(MotorCommand.damping())
    touched = ()
    for _ in range(150):
        backend.step(0.02)
        touched = backend.ground_contacts()
        if touched:
            break
    assert touched and all(name not in ("left_ankle_roll_link", "right_ankle_roll_link") for name in touched)


def test_estimator_pelvis_height_matches_the_simulator():
    backend = MujocoBackend()
    backend.reset()
    backend.step(0.3)
    state = backend.read_state()
    est = StateEstimator().update(state)
    assert est.pelvis_height_m == pytest.approx(state.base_pos_w_m[2], abs=0.01)


def _stand_launch(seconds: float) -> LaunchFile:
    launch = LaunchFile(name="fall_test")
    launch.input.timeline = [Segment(seconds)]
    launch.output.video, launch.output.plot, launch.viewer = False, False, False
    return launch


def test_a_robot_damped_for_another_reason_that_collapses_has_fallen():
    # An e-stop (not a fall) damps the robot; it then collapses: the run must say it fell, and why.
    loop = build_loop(_stand_launch(4.0))
    loop.reset()
    loop.run(0.5)
    assert not loop.fell
    loop.safety.estop("test", loop.time_s)
    loop.run(3.5)
    assert loop.fell and loop.fall.kind in ("body_contact", "pelvis_low")
    assert loop.fall.t_s > 0.5
    assert any(e.kind == "fall" for e in loop.events)


def test_standing_run_reports_no_fall_and_summary_names_a_fall():
    result = run(_stand_launch(2.0), progress=False)
    assert not result.fell and result.fall is None
    assert "no fall" in format_summary(result)
    result.fall, result.fell = {"t_s": 1.5, "kind": "body_contact", "detail": "left_knee_link on the ground"}, True
    assert "FELL at 1.50 s: left_knee_link on the ground" in format_summary(result)
