"""PoseFusion (estimation/external_pose.py): an external pose carried to now by the odometry's motion
since its stamp, stale / future / jumping / non-finite poses refused by name and counted, the fused
pose pulled toward accepted ones, and the external frame aligned at the first pose (frame start)."""

from __future__ import annotations

import math

import pytest

from g1_control.errors import LaunchFileError
from g1_control.estimation.external_pose import ExternalPoseConfig, Planar, PoseFusion, PoseSample


def _walk(fusion: PoseFusion, seconds: float, vx: float = 0.5, drift: float = 1.0, wz: float = 0.0, dt: float = 0.01):
    """Odometry of a walk at vx (reading `drift` times the true distance) from t=0: yields (t, true x, true y)."""
    x = y = yaw = 0.0
    for k in range(round(seconds / dt) + 1):
        t = k * dt
        fusion.update(Planar(t, drift * x, drift * y, yaw))
        yield t, x, y, yaw
        x += vx * math.cos(yaw) * dt
        y += vx * math.sin(yaw) * dt
        yaw += wz * dt


def _config(**changes) -> ExternalPoseConfig:
    cfg = ExternalPoseConfig(interface="lo", frame="scene", correction_tau_s=0.2)
    for k, v in changes.items():
        setattr(cfg, k, v)
    return cfg


def test_a_late_pose_is_carried_to_now_by_the_odometrys_motion_since_its_stamp():
    """Odometry reading 80 % of a 0.5 m/s walk; external poses 0.2 s late: the fused pose follows the true
    pose now, not where the robot was 0.2 s ago (10 cm behind). What is left: the odometry's own 20 %
    error over the 0.2 s it carries each pose (2 cm) and the filter's lag between poses (2 cm)."""
    fusion = PoseFusion(_config(max_age_s=0.5))
    truth = {}
    for t, x, _y, _ in _walk(fusion, 6.0, drift=0.8):
        truth[round(t, 2)] = x
        stamp = round(t - 0.2, 2)
        if stamp >= 0 and round(t * 100) % 5 == 0:
            assert fusion.measure(PoseSample(stamp, truth[stamp], 0.0, 0.0))
    assert fusion.fused is not None
    assert fusion.fused.x_m == pytest.approx(x, abs=0.05)  # uncompensated: 12 cm behind
    assert fusion.counters.accepted > 100 and sum(fusion.counters.rejected.values()) == 0


def test_stale_future_jumping_and_invalid_poses_are_refused_by_name():
    fusion = PoseFusion(_config(max_age_s=0.3, max_jump_m=0.2))
    for _ in _walk(fusion, 1.0, vx=0.0):
        pass
    assert not fusion.measure(PoseSample(0.5, 0.0, 0.0, 0.0))  # 0.5 s old
    assert fusion.counters.last_rejection == "stale: 0.500 s old (max_age_s 0.3)"
    assert not fusion.measure(PoseSample(1.2, 0.0, 0.0, 0.0))
    assert fusion.counters.last_rejection.startswith("future: stamped 0.200 s after now")
    assert not fusion.measure(PoseSample(0.95, 0.5, 0.0, 0.0))
    assert fusion.counters.last_rejection.startswith("jump: 0.500 m / 0.0 deg from the fused pose (max_jump_m 0.2")
    assert not fusion.measure(PoseSample(0.95, 0.0, 0.0, math.radians(40)))  # heading jump (max 0.5 rad = 28.6 deg)
    assert not fusion.measure(PoseSample(0.95, math.nan, 0.0, 0.0))
    assert fusion.counters.last_rejection.startswith("invalid: non-finite field")
    assert fusion.counters.rejected == {"stale": 1, "future": 1, "jump": 2, "invalid": 1}
    assert fusion.fused is not None and (fusion.fused.x_m, fusion.fused.yaw_rad) == (0.0, 0.0)  # nothing moved it
    assert fusion.measure(PoseSample(0.95, 0.1, 0.0, 0.0)) and fusion.fused.x_m > 0.0
    assert "1 accepted, refused: 1 stale, 1 future, 2 jump, 1 invalid" in fusion.describe()


def test_a_pose_stamped_before_the_odometry_history_is_refused_as_stale():
    """Just after the start the odometry history is shorter than max_age_s: a pose stamped before its
    first sample cannot be carried to now and is refused (stale), not compensated from the first sample."""
    fusion = PoseFusion(_config(max_age_s=0.3))
    fusion.update(Planar(1.0, 0.0, 0.0, 0.0))
    fusion.update(Planar(1.01, 0.005, 0.0, 0.0))
    assert not fusion.measure(PoseSample(0.9, 0.0, 0.0, 0.0))
    assert fusion.counters.last_rejection == "stale: stamped 0.110 s ago, before the odometry history"
    assert fusion.counters.accepted == 0 and fusion.fused == Planar(1.01, 0.005, 0.0, 0.0)


def test_after_an_outage_agreeing_poses_are_reacquired_and_a_lone_wild_pose_is_not():
    """Odometry reading 70 % of a 0.5 m/s walk; motion capture lost from 1 s to 5 s: 0.6 m of drift, past
    max_jump_m. The poses after the outage agree with each other, so after `reacquire_poses` of them the
    fused pose is the true pose again; before that, and for a lone wild pose later, nothing moves it."""
    fusion = PoseFusion(_config(max_jump_m=0.3, reacquire_poses=5))
    wild_done = False
    for t, x, _y, _ in _walk(fusion, 8.0, drift=0.7):
        tick = round(t * 100)
        if tick % 5 or 100 < tick < 500:
            continue
        if tick == 700 and not wild_done:  # one pose 1 m off, among good ones
            wild_done = True
            assert not fusion.measure(PoseSample(t, x + 1.0, 0.0, 0.0))
            continue
        before = fusion.fused
        accepted = fusion.measure(PoseSample(t, x, 0.0, 0.0))
        if 500 <= tick < 520:  # the first four poses after the outage: refused as jumps, fused pose untouched
            assert not accepted and fusion.fused == before
            assert fusion.counters.last_rejection.startswith("jump: ")
        else:
            assert accepted, (t, fusion.counters.last_rejection)
        if tick == 520:  # the fifth agreeing pose: the fused pose is reset onto it
            assert fusion.fused is not None and fusion.fused.x_m == pytest.approx(x, abs=0.01)
    assert fusion.counters.reacquired == 1 and fusion.counters.max_reacquire_m == pytest.approx(0.3 * 0.5 * 4.0, abs=0.1)
    assert fusion.counters.rejected["jump"] == 5  # four while re-acquiring, one wild
    assert fusion.fused is not None and fusion.fused.x_m == pytest.approx(x, abs=0.03)
    assert "re-acquired 1x after an outage" in fusion.describe()


def test_disagreeing_jumps_and_reacquire_poses_0_never_reset_the_pose():
    """Jumping poses that scatter (each 0.2 m from the last beyond the tolerance) never add up to a
    re-acquisition; nor do agreeing ones with reacquire_poses 0."""
    for changes, scatter in (({"reacquire_poses": 3}, 0.2), ({"reacquire_poses": 0}, 0.0)):
        fusion = PoseFusion(_config(max_jump_m=0.3, **changes))
        for k, _ in enumerate(_walk(fusion, 1.0, vx=0.0)):
            if k % 5 == 0 and k:
                assert not fusion.measure(PoseSample(k * 0.01, 1.0 + scatter * (k // 5 % 2), 0.0, 0.0))
        assert fusion.counters.reacquired == 0 and fusion.fused is not None and fusion.fused.x_m == 0.0


def test_frame_start_aligns_the_external_frame_at_the_first_pose():
    """Motion capture whose origin is 3 m away and turned 90 deg: the fused pose stays in the start frame,
    and a later pose corrects the odometry's 20 % under-reading there."""
    fusion = PoseFusion(_config(frame="start"))

    def mocap(x: float, y: float, yaw: float) -> tuple[float, float, float]:
        return 3.0 - y, 1.0 + x, yaw + math.pi / 2  # the start frame seen from the mocap's

    for t, x, y, yaw in _walk(fusion, 4.0, drift=0.8, wz=0.2):
        if round(t * 100) % 10 == 0:
            assert fusion.measure(PoseSample(t, *mocap(x, y, yaw)))
    assert fusion.fused is not None
    assert (fusion.fused.x_m, fusion.fused.y_m) == pytest.approx((x, y), abs=0.02)
    assert fusion.fused.yaw_rad == pytest.approx(yaw, abs=0.01)


def test_without_poses_the_fused_pose_is_the_odometry():
    fusion = PoseFusion(_config())
    for _ in _walk(fusion, 2.0, drift=0.8):
        pass
    assert fusion.fused is not None and fusion.fused.x_m == pytest.approx(0.8 * 0.5 * 2.0, abs=0.01)


@pytest.mark.parametrize("changes, message", [
    ({"interface": None}, "estimation.external_pose.interface: an external pose input must name the network interface"),
    ({"topic": "rt/mocap"}, "estimation.external_pose.topic: 'rt/mocap' is not a ROS 2 topic name"),
    ({"max_jump_m": -1.0}, "estimation.external_pose.max_jump_m: must be a positive number, got -1.0"),
    ({"max_age_s": 5.0}, "estimation.external_pose.max_age_s: 5.0 s is longer than the 2 s of odometry kept"),
    ({"domain": 300}, "estimation.external_pose.domain: 300 is not a DDS domain id"),
    ({"reacquire_poses": -1}, "estimation.external_pose.reacquire_poses: must be a whole number of poses 0..1000"),
    ({"reacquire_poses": 2.5}, "estimation.external_pose.reacquire_poses: must be a whole number of poses 0..1000"),
    ({"reacquire_tolerance_m": 0.5}, "estimation.external_pose.reacquire_tolerance_m: 0.5 m must be below max_jump_m"),
])
def test_bad_settings_are_refused_naming_the_key(changes, message):
    with pytest.raises(LaunchFileError) as err:
        _config(**changes).validate("estimation.external_pose")
    assert str(err.value).startswith(message)


def test_the_launch_file_refuses_an_external_pose_that_nothing_steers_by():
    from g1_control.launch.schema import parse_launch

    with pytest.raises(LaunchFileError, match="estimation.external_pose: the external pose is fused into the robot's "
                                              "estimate, which this MuJoCo run does not steer by"):
        parse_launch({"name": "x", "estimation": {"external_pose": {"interface": "lo"}}})
    with pytest.raises(LaunchFileError, match="estimation.steer_by: ground_truth needs a simulator's ground truth"):
        parse_launch({"name": "x", "backend": {"type": "unitree_dds", "interface": "lo"},
                      "estimation": {"steer_by": "ground_truth"}})
    with pytest.raises(LaunchFileError, match="estimation.perception: objects are placed with the robot's estimate"):
        parse_launch({"name": "x", "estimation": {"perception": {"interface": "lo"}}})
    with pytest.raises(LaunchFileError, match="estimation.perception.interface: a perception input must name"):
        parse_launch({"name": "x", "estimation": {"steer_by": "estimate", "perception": {}}})
    with pytest.raises(LaunchFileError, match=r"estimation.perception.max_age_s: 3.0 is outside \(0, 2\] s"):
        parse_launch({"name": "x", "estimation": {"steer_by": "estimate", "perception": {"interface": "lo",
                                                                                        "max_age_s": 3}}})
    launch = parse_launch({"name": "x", "estimation": {"steer_by": "estimate", "external_pose": {"interface": "lo"}}})
    assert launch.steers_by_estimate() and launch.estimation.external_pose is not None
    assert not parse_launch({"name": "x"}).steers_by_estimate()
