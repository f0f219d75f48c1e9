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


def test_the_fall_judges_bounds_and_words_exactly():
    """At the limits (tilt exactly max_tilt_rad, pelvis exactly min_pelvis_height_m) the robot has not
    fallen; just past them it has, at that tick, with the words the summary shows; bodies on the
    ground are all named; a bad height names the `fall.` key by default."""
    import math

    from g1_control.errors import SafetyConfigError
    from g1_control.safety.fall import FallConfig, FallMonitor

    def tilted(angle: float) -> np.ndarray:
        return np.array([math.cos(angle / 2), math.sin(angle / 2), 0.0, 0.0])

    from g1_control.rotations import tilt_rad

    upright = np.array([1.0, 0.0, 0.0, 0.0])
    limit = float(tilt_rad(tilted(0.5)))  # 0.5 rad, as the monitor computes it
    monitor = FallMonitor(FallConfig(min_pelvis_height_m=0.4), max_tilt_rad=limit)
    assert monitor.update(1.0, tilted(0.5), 0.4, ()) is None  # both exactly at their limits
    fall = monitor.update(1.5, tilted(0.5 + 1e-4), 0.7, None)
    assert fall is not None and (fall.t_s, fall.kind) == (1.5, "tilt")
    assert fall.detail == "pelvis tilted 0.50 rad (limit 0.50)" and str(fall) == f"{fall.detail} at 1.50 s"
    monitor = FallMonitor(FallConfig(min_pelvis_height_m=0.4), max_tilt_rad=0.5)
    fall = monitor.update(2.25, upright, 0.3999, None)
    assert fall is not None and (fall.t_s, fall.kind, fall.detail) == (2.25, "pelvis_low", "pelvis at 0.40 m (limit 0.40)")
    monitor = FallMonitor(FallConfig(allowed_contacts=("left_hand",)))
    assert monitor.update(3.0, upright, 0.7, ("left_hand",)) is None
    fall = monitor.update(3.5, upright, 0.7, ("left_knee_link", "left_hand", "right_knee_link"))
    assert fall is not None and (fall.t_s, fall.kind) == (3.5, "body_contact")
    assert fall.detail == "left_knee_link, right_knee_link on the ground"
    with pytest.raises(SafetyConfigError, match=r"^fall\.min_pelvis_height_m is 0.0; it must lie in"):
        FallConfig(min_pelvis_height_m=0.0).validate()


def test_first_fault_is_the_first_unplanned_trip():
    """Planned trips (stop, control time over, a signal) and events that trip nothing are passed over."""
    from g1_control.loop.control_loop import first_fault

    stop = {"kind": "estop", "trips": True, "planned": True}
    note = {"kind": "clamp", "trips": False, "planned": False}
    crc = {"kind": "crc_burst", "trips": True, "planned": False}
    assert first_fault([stop, note, crc, dict(crc, kind="later")]) is crc
    assert first_fault([stop, note]) is None
    assert first_fault([{"kind": "old", "trips": True}]) == {"kind": "old", "trips": True}  # planned absent: a fault


def test_the_monitors_default_tilt_limit_is_one_radian():
    from g1_control.safety.fall import FallMonitor

    def tilted(angle: float) -> np.ndarray:
        return np.array([np.cos(angle / 2), np.sin(angle / 2), 0.0, 0.0])

    assert FallMonitor().update(0.0, tilted(0.95), 0.7, None) is None
    fall = FallMonitor().update(0.0, tilted(1.05), 0.7, None)
    assert fall is not None and fall.detail == "pelvis tilted 1.05 rad (limit 1.00)"
