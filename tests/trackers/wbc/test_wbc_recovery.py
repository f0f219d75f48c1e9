"""Pushed while walking, the whole-body controller's recovery steps keep it up: pushes of `g1 bench
locomotion`'s grid (150 N for 0.2 s on the pelvis, walking 0.5 m/s) in lockstep MuJoCo through the
one loop builder, judged from the simulator (pelvis height, no fall, no safety trip). Chaotic near its
limits, the controller survives only some of the grid (9 of 20); these are survived, and each part
that saves some of them is taken away in turn (so a test goes red without it):
  WbcConfig.recovery_com_lower_m   the CoM held 0.08 m lower in a pushed recovery step (without:
                                   front_2 and front_3 fell);
  GaitConfig.recovery_max_width_m  a recovery step may land 0.6 m wide (at the plain 0.45 m: left_1
                                   fell within the settling time);
  WbcConfig.recovery_swing_weight  the swing foot held harder in a recovery step (at its plain walking
                                   weight the QP swings the leg back instead of stepping: front_3 and
                                   left_2 fell; on MuJoCo 4.0.0 front_3 only);
  GaitConfig.min_swing_s 0.15      a recovery step made sooner may swing only 0.15 s (0.2: back_2
                                   and left_1 fell);
  WbcConfig.swing_max_accel_mps2   the swing foot's re-planned reference acceleration capped (uncapped:
                                   right_0 fell, ankle pitch over-speed; left_2 and back_2 trip too,
                                   left_2 after the settling time).
Two options, off by default (they save pushes but front_3 then trips; they act only after a push told
by GaitConfig.push_detect_m, so the random velocity timelines' pushed steps leave them be, gait.py),
are shown to save pushes that fall without them:
  GaitConfig.after_push_steps 1    the step after a pushed step keeps the CoM lowered (front_1 survives;
                                   it falls with the defaults);
  GaitConfig.early_lift_dcm_error_m  with it, the DCM 0.2 m off its plan in a double support lifts the
                                   swing foot at once (right_3 survives; with after_push_steps alone it
                                   falls)."""

import functools

import pytest

from g1_control.tools import bench_locomotion as bench
from g1_control.trackers.wbc import tracker as wbc_tracker
from g1_control.trackers.wbc.gait import GaitConfig

UPRIGHT_PELVIS_M = 0.6
"""Ground-truth pelvis height the robot stays above (it walks at ~0.68 m; a fall ends at 0.4)."""
SURVIVED = ("push_front_0", "push_front_2", "push_front_3", "push_front_4", "push_left_2", "push_right_0",
            "push_right_4")


def run_push(name: str):
    case = next(c for c in bench.push_cases() if c.name == name)
    return bench.run_case("wbc", case, walk_s=0.0)


def without(monkeypatch, **changes) -> None:
    """The controller the loop builder makes from now on, with `changes` to its WbcConfig."""
    monkeypatch.setattr(wbc_tracker, "WbcConfig", functools.partial(wbc_tracker.WbcConfig, **changes))


def assert_fell(names) -> None:
    """At least one of the named pushes is not survived. Each of them is survived with the part taken
    away (SURVIVED, or asserted in the test), so any fall shows the part matters. Not all of them: which
    pushes a part saves moves with the floating-point environment (stop 45, a fresh install with MuJoCo
    4.0.0: without the recovery swing weight front_3 fell and left_2 walked on, as it did with 3.17.0)."""
    rows = [run_push(name) for name in names]
    assert any(not row.pushes_survived for row in rows), [(r.case, r.min_pelvis_m, r.trip) for r in rows]


@pytest.mark.parametrize("name", SURVIVED)
def test_recovery_steps_survive_a_push(name):
    row = run_push(name)
    assert not row.fell and not row.trip, f"{name}: {row.fall or row.trip}"
    assert row.pushes_survived == row.pushes == 1
    assert row.min_pelvis_m > UPRIGHT_PELVIS_M


def test_without_the_recovery_swing_weight_front_3_and_left_2_fell(monkeypatch):
    without(monkeypatch, recovery_swing_weight=wbc_tracker.WbcConfig().swing_foot.weight)
    assert_fell(["push_front_3", "push_left_2"])


def test_with_a_longer_minimum_swing_back_2_and_left_1_fell(monkeypatch):
    assert run_push("push_back_2").pushes_survived == run_push("push_left_1").pushes_survived == 1
    without(monkeypatch, gait=GaitConfig(min_swing_s=0.2))
    assert_fell(["push_back_2", "push_left_1"])


def test_with_the_swing_acceleration_uncapped_right_0_fell(monkeypatch):
    without(monkeypatch, swing_max_accel_mps2=1e9)
    assert_fell(["push_right_0"])


def test_without_the_lower_com_in_recovery_steps_front_2_and_front_3_fell(monkeypatch):
    without(monkeypatch, recovery_com_lower_m=0.0)
    assert_fell(["push_front_2", "push_front_3"])


def test_with_recovery_steps_no_wider_than_plain_steps_left_1_fell(monkeypatch):
    assert run_push("push_left_1").pushes_survived == 1
    without(monkeypatch, gait=GaitConfig(recovery_max_width_m=GaitConfig().max_width_m))
    assert_fell(["push_left_1"])


PUSH_OPTIONS = {"after_push_steps": 1, "early_lift_dcm_error_m": 0.2}


def test_with_the_step_after_a_push_held_low_front_1_survives(monkeypatch):
    assert_fell(["push_front_1"])
    without(monkeypatch, gait=GaitConfig(**PUSH_OPTIONS))
    row = run_push("push_front_1")
    assert row.pushes_survived == 1 and not row.fell and not row.trip, row.trip


def test_with_the_early_lift_too_right_3_survives(monkeypatch):
    without(monkeypatch, gait=GaitConfig(**{**PUSH_OPTIONS, "early_lift_dcm_error_m": float("inf")}))
    assert_fell(["push_right_3"])
    without(monkeypatch, gait=GaitConfig(**PUSH_OPTIONS))
    row = run_push("push_right_3")
    assert row.pushes_survived == 1 and not row.fell and not row.trip, row.trip
