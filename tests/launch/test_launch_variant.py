"""A launch file's robot variant (backend.expected_variant) is what runs: the simulator builds it,
the whole-body controller models it, and a tracker that does not fit it is refused by joint name."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from g1_control.cli.main import main
from g1_control.errors import LaunchFileError, PolicyMismatchError
from g1_control.launch.builder import build_loop
from g1_control.launch.schema import load_launch, parse_launch
from g1_control.launch.variant import check_policy_fits, check_tracker_fits
from g1_control.robot import g1
from g1_control.trackers.wbc.tracker import WholeBodyTracker
from tests.paths import LAUNCH_DIR

WALK_23 = LAUNCH_DIR / "sim_wbc_walk_23dof.yaml"
DROPPED = ("waist_roll_joint, waist_pitch_joint, left_wrist_pitch_joint, left_wrist_yaw_joint, "
           "right_wrist_pitch_joint, right_wrist_yaw_joint")


def test_check_refuses_the_29dof_policy_for_the_23dof_robot_by_joint_name(capsys):
    assert main(["launch", str(WALK_23), "--check", "--set", "tracker.type=policy"]) == 1
    err = capsys.readouterr().err
    assert (f"tracker.policy: policy 'holosoma-loco-ppo' commands 29 joints, and the g1_23dof G1 "
            f"(backend.expected_variant, 23 DoF) has no {DROPPED}; use a policy made for g1_23dof, or tracker.type "
            "wbc") in err


def test_check_passes_the_23dof_launch_file_and_names_its_variant(capsys):
    assert main(["launch", str(WALK_23), "--check"]) == 0
    assert "OK (sim_wbc_walk_23dof: mujoco lockstep, g1_23dof, tracker wbc, 9.8 s" in capsys.readouterr().out


def test_g1_launch_refuses_the_29dof_policy_before_anything_runs():
    launch = load_launch(WALK_23, overrides=["tracker.type=policy", "generator.type=velocity",
                                             "rates.tracker_hz=50"])
    with pytest.raises(PolicyMismatchError, match=f"has no {DROPPED}"):
        build_loop(launch)


def test_the_29dof_policy_fits_the_29dof_robot():
    check_tracker_fits(load_launch(LAUNCH_DIR / "sim_walk.yaml"))


def test_wbt_is_refused_on_the_23dof_robot():
    launch = parse_launch({"name": "wbt23", "backend": {"expected_variant": "g1_23dof"}, "rates": {"tracker_hz": 50},
                           "tracker": {"type": "wbt"}, "generator": {"type": "scripted", "reference": "stand"},
                           "input": {"type": "scripted", "timeline": [{"duration_s": 1.0}]}})
    with pytest.raises(PolicyMismatchError, match=f"tracker.type wbt: .* has no {DROPPED}; use tracker.type wbc"):
        check_tracker_fits(launch)


def test_the_tracking_layer_walks_by_the_policy_and_is_refused_on_the_23dof_robot():
    """tracker.type layer runs the 29-DoF walking policy between its whole-body phases: it is
    checked against the variant like tracker.type policy, and refused by joint name."""
    launch = load_launch(WALK_23, overrides=["tracker.type=layer", "generator.type=velocity",
                                             "rates.tracker_hz=100"])
    with pytest.raises(PolicyMismatchError, match=f"policy 'holosoma-loco-ppo' commands 29 joints, .* has no {DROPPED}"):
        check_tracker_fits(launch)


def test_a_23dof_policy_on_the_29dof_robot_leaves_joints_uncommanded():
    policy = SimpleNamespace(name="base23", joint_names=tuple(g1.JOINT_NAMES[i] for i in g1.G1_23DOF.active_joints))
    with pytest.raises(PolicyMismatchError, match=f"policy 'base23' commands 23 joints and leaves {DROPPED} of the "
                                                  "g1_29dof G1"):
        check_policy_fits(policy, load_launch(LAUNCH_DIR / "sim_walk.yaml"))
    check_policy_fits(policy, load_launch(WALK_23))  # fits the robot it was made for


def test_the_variant_is_not_a_reference_parameter():
    with pytest.raises(LaunchFileError, match="reference_params: variant not a parameter of reference 'stand'"):
        parse_launch({"name": "x", "tracker": {"type": "wbc"}, "rates": {"tracker_hz": 250},
                      "generator": {"type": "scripted", "reference": "stand", "reference_params": {"variant": 4}},
                      "input": {"type": "scripted", "timeline": [{"duration_s": 1.0}]}})


def _run(loop, seconds: float):
    loop.reset()
    loop.scheduler.run(round(seconds * loop.rates.lowlevel_hz), stop=lambda: loop.fell)
    return loop.log.arrays()


def test_the_shipped_23dof_launch_file_walks_the_23dof_robot_under_the_wbc():
    loop = build_loop(load_launch(WALK_23))
    assert loop.backend.model.nu == 23 and loop.backend.read_state().mode_machine == 4
    assert isinstance(loop.tracker, WholeBodyTracker) and loop.tracker.dyn.variant is g1.G1_23DOF
    log = _run(loop, loop.generator.trajectory.duration_s)
    assert not loop.fell, loop.fall
    pos = log["base_pos_m"]  # the simulator's ground truth
    print(f"\n23-DoF WBC walk: {pos[-1, 0] - pos[0, 0]:.2f} m forward, {pos[-1, 1] - pos[0, 1]:+.3f} m sideways, "
          f"pelvis {pos[:, 2].min():.3f}-{pos[:, 2].max():.3f} m")
    assert pos[-1, 0] - pos[0, 0] > 1.5 and abs(pos[-1, 1] - pos[0, 1]) < 0.1 and pos[:, 2].min() > 0.65
    assert not log["q_rad"][:, ~g1.G1_23DOF.active_mask].any()


def test_the_23dof_robot_reaches_under_the_wbc():
    from g1_control.tools.wbc_evaluate import figures_of

    loop = build_loop(load_launch(WALK_23, overrides=["generator.reference=lean_reach"]))
    trajectory = loop.generator.trajectory
    _run(loop, trajectory.duration_s)
    figures = figures_of(trajectory, loop, "wbc", 0.0)
    print(f"\n23-DoF WBC reach: hand {figures.hand_error_m * 1000:.1f} mm from its target (ground-truth base + "
          f"measured joints), joint RMS {figures.joint_rms_rad:.4f} rad")
    assert not loop.fell and figures.hand_error_m < 0.02
    assert np.isfinite(figures.joint_rms_rad) and figures.joint_rms_rad < 0.05


def test_dex3_hands_on_the_23dof_robot_are_refused_in_the_launch_file():
    with pytest.raises(LaunchFileError, match="backend.hands: Dex3 hands are modelled on the 29-DoF G1 only; "
                                              "expected_variant is g1_23dof"):
        load_launch(WALK_23, overrides=["backend.hands=dex3"])


def test_the_wbc_walks_the_g1_with_dex3_hands_on_their_model():
    loop = build_loop(load_launch(LAUNCH_DIR / "sim_wbc_walk.yaml", overrides=["backend.hands=dex3"]))
    assert loop.backend.model.njnt == 1 + 29 + 14
    assert loop.tracker.dyn.mass_kg == pytest.approx(34.394, abs=1e-3)  # the hands' mass, not the rubber hands'
    log = _run(loop, loop.generator.trajectory.duration_s)
    pos = log["base_pos_m"]
    print(f"\nDex3 WBC walk: {pos[-1, 0] - pos[0, 0]:.2f} m forward, pelvis min {pos[:, 2].min():.3f} m")
    assert not loop.fell and pos[-1, 0] - pos[0, 0] > 1.5
