"""Pushed while walking, the whole-body controller's recovery steps keep it up: pushes of `g1 bench
locomotion`'s grid (150 N for 0.2 s on the pelvis, walking 0.5 m/s) in lockstep MuJoCo through the
one loop builder, judged from the simulator (pelvis height, no fall, no safety trip). Chaotic near its
limits, the controller survives only some of the grid (12 of 20 on the Coulomb floor of stop 46); these
are survived, and each part that saves some of them is taken away in turn (so a test goes red without
it; measured on the Coulomb floor, the grid's survivors without the part in brackets):
  GaitConfig.after_push_steps 1    the step after a pushed step keeps the CoM lowered (without: front_1,
                                   front_3 and right_3 fell; on by default since stop 46);
  WbcConfig.recovery_com_lower_m   the CoM held 0.08 m lower in a pushed recovery step (without:
                                   front_1, front_3, back_0 and right_3 fell);
  GaitConfig.recovery_max_width_m  a recovery step may land 0.6 m wide (at the plain 0.45 m: left_1
                                   and right_3 fell);
  GaitConfig.min_swing_s 0.15      a recovery step made sooner may swing only 0.15 s (0.2: front_1,
                                   left_1 and right_3 fell);
  WbcConfig.swing_max_accel_mps2   the swing foot's re-planned reference acceleration capped (uncapped:
                                   back_2, right_3 and right_4 fell).
Two parts that saved pushes on MuJoCo's default (soft, pyramidal) friction save none of this grid on
the Coulomb floor, so no test here shows them: WbcConfig.recovery_swing_weight (at the plain swing
weight the same 12 survive; 9 and 9 with after_push_steps 0; 150 N at phases shifted by 0.1 stride:
9 and 9; 120 N: 10 against 11) and GaitConfig.early_lift_dcm_error_m 0.2 (12 with and without; shifted
by 0.1 stride: 11 and 11). Measured, one machine, /tmp scratch runs of bench_locomotion.run_case."""

import functools

import pytest

from g1_control.tools import bench_locomotion as bench
from g1_control.trackers.wbc import tracker as wbc_tracker
from g1_control.trackers.wbc.gait import GaitConfig

UPRIGHT_PELVIS_M = 0.55
"""Ground-truth pelvis height the robot stays above (it walks at ~0.68 m and holds its CoM 0.08 m lower
in a pushed step and the step after it: the survivors' lowest 0.579-0.620 m, measured; a fall ends at 0.4)."""
SURVIVED = ("push_front_0", "push_front_1", "push_front_2", "push_front_3", "push_front_4", "push_back_0",
            "push_back_2", "push_left_1", "push_left_2", "push_right_0", "push_right_3", "push_right_4")


def run_push(name: str):
    case = next(c for c in bench.push_cases() if c.name == name)
    return bench.run_case("wbc", case, walk_s=0.0)


def without(monkeypatch, **changes) -> None:
    """The controller the loop builder makes from now on, with `changes` to its WbcConfig."""
    monkeypatch.setattr(wbc_tracker, "WbcConfig", functools.partial(wbc_tracker.WbcConfig, **changes))


def assert_fell(names) -> None:
    """At least one of the named pushes is not survived. Each of them is survived with the part in place
    (SURVIVED), so any fall shows the part matters. Not all of them: which
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


def test_without_the_step_after_a_push_held_low_front_1_front_3_and_right_3_fell(monkeypatch):
    without(monkeypatch, gait=GaitConfig(after_push_steps=0))
    assert_fell(["push_front_1", "push_front_3", "push_right_3"])


def test_with_a_longer_minimum_swing_front_1_and_left_1_fell(monkeypatch):
    without(monkeypatch, gait=GaitConfig(min_swing_s=0.2))
    assert_fell(["push_front_1", "push_left_1"])


def test_with_the_swing_acceleration_uncapped_back_2_and_right_4_fell(monkeypatch):
    without(monkeypatch, swing_max_accel_mps2=1e9)
    assert_fell(["push_back_2", "push_right_4"])


def test_without_the_lower_com_in_recovery_steps_front_3_and_back_0_fell(monkeypatch):
    without(monkeypatch, recovery_com_lower_m=0.0)
    assert_fell(["push_front_3", "push_back_0"])


def test_with_recovery_steps_no_wider_than_plain_steps_left_1_fell(monkeypatch):
    without(monkeypatch, gait=GaitConfig(recovery_max_width_m=GaitConfig().max_width_m))
    assert_fell(["push_left_1"])
