"""The launch file's `ik:` section: defaults that leave existing files as they were, named errors,
and the builder making the IK stage from it, apart from the generator and the tracker."""

import dataclasses
import typing
from pathlib import Path

import pytest

from g1_control.errors import LaunchFileError
from g1_control.ik.retargeter import IKConfig
from g1_control.ik.solver import BACKENDS
from g1_control.ik.stage import IKStage
from g1_control.launch.builder import make_generator, make_ik
from g1_control.launch.schema import IKSection, load_launch, parse_launch
from g1_control.robot import g1
from g1_control.types import Command, RobotState

REPO = Path(__file__).resolve().parents[2]


def minimal(**extra):
    d = {"name": "t", "input": {"type": "scripted", "timeline": [{"duration_s": 1.0, "vx_mps": 0.2}]}}
    d.update(extra)
    return d


def test_every_setting_is_an_ik_config_field_and_the_backends_agree():
    names = {f.name for f in dataclasses.fields(IKConfig)}
    assert {f.name for f in dataclasses.fields(IKSection)} <= names
    assert typing.get_args(typing.get_type_hints(IKSection)["backend"]) == BACKENDS


def test_a_file_without_the_section_gets_the_loops_ik():
    stage = make_ik(parse_launch(minimal()))
    cfg = stage.ik.config
    # What the generator's retargeter used before the IK was a stage of its own: the legs are the
    # walking policy's (no held contacts, no CoM cost), one QP step per 50 Hz tick.
    assert isinstance(stage, IKStage)
    assert not cfg.hold_contacts and cfg.com_cost == (0.0, 0.0, 0.0) and cfg.iterations == 1
    assert cfg.dt_s == 0.02 and cfg.backend == "daqp" and cfg.root_cost == (10.0, 5.0)


def test_settings_and_the_tracker_rate_reach_the_solver():
    launch = parse_launch(minimal(rates={"tracker_hz": 100}, ik={
        "iterations": 3, "hold_contacts": True, "com_cost": [2, 2, 0], "velocity_limit_scale": 0.5,
        "frame_costs": {"right_rubber_hand": [20, 0]}}))
    cfg = make_ik(launch).ik.config
    assert cfg.dt_s == 0.01 and cfg.iterations == 3 and cfg.hold_contacts and cfg.com_cost == (2.0, 2.0, 0.0)
    assert cfg.velocity_limit_scale == 0.5 and cfg.frame_costs == {"right_rubber_hand": (20.0, 0.0)}


@pytest.mark.parametrize("ik, message", [
    ({"iterations": 0}, r"ik.iterations: 0 must be >= 1 \(QP steps per tick\)"),
    ({"backend": "osqp"}, "ik.backend: expected one of 'daqp', 'proxqp', got 'osqp'"),
    ({"posture_cost": -1}, r"ik.posture_cost: -1.0 has a negative cost \(costs are >= 0; 0 disables\)"),
    ({"root_cost": [10, -5]}, r"ik.root_cost: \[10.0, -5.0\] has a negative cost"),
    ({"frame_costs": {"left_rubber_hand": [1, -1]}}, "ik.frame_costs.left_rubber_hand: .* has a negative cost"),
    ({"com_cost": [1, 1]}, "ik.com_cost: expected 3 items, got 2"),
    ({"velocity_limit_scale": 1.5}, r"ik.velocity_limit_scale: 1.5 is outside \(0, 1\]"),
    ({"joint_margin_rad": -0.1}, r"ik.joint_margin_rad: -0.1 is outside \[0, 0.2\) rad"),
    ({"hold_contact": True}, "ik: unknown key 'hold_contact'; allowed: backend, iterations"),
    # every cost named by its own key, and the bounds at their edges (mutation survivors, issue 26)
    ({"com_cost": [1, -1, 1]}, r"ik.com_cost: \[1.0, -1.0, 1.0\] has a negative cost"),
    ({"default_frame_cost": [1, -2]}, r"ik.default_frame_cost: \[1.0, -2.0\] has a negative cost"),
    ({"damping_cost": -0.5}, r"ik.damping_cost: -0.5 has a negative cost"),
    ({"smoothness_cost": -2}, r"ik.smoothness_cost: -2.0 has a negative cost"),
    ({"velocity_limit_scale": 0.0}, r"^x.yaml: ik.velocity_limit_scale: 0.0 is outside \(0, 1\] \(a fraction of the "
                                    r"motors' velocity limits\)$"),
    ({"joint_margin_rad": 0.2}, r"ik.joint_margin_rad: 0.2 is outside \[0, 0.2\) rad"),
    ({"joint_margin_rad": 1.0}, r"ik.joint_margin_rad: 1.0 is outside \[0, 0.2\) rad"),
])
def test_bad_settings_are_refused_with_the_key(ik, message):
    with pytest.raises(LaunchFileError, match=message):
        parse_launch(minimal(ik=ik), "x.yaml")


def test_an_unknown_frame_is_refused_when_the_stage_is_built():
    launch = parse_launch(minimal(ik={"frame_costs": {"left_hnad": [5, 1]}}))
    with pytest.raises(LaunchFileError, match="ik.frame_costs.left_hnad: .*left_hnad"):
        make_ik(launch)


def test_overrides_reach_the_section():
    launch = load_launch(REPO / "launch" / "sim_walk.yaml", overrides=["ik.iterations=2", "ik.backend=proxqp"])
    assert launch.ik.iterations == 2 and launch.ik.backend == "proxqp"


def test_the_shipped_generator_launch_file_states_the_defaults():
    shipped = load_launch(REPO / "launch" / "sim_generator.yaml")
    assert shipped.ik == IKSection()


def test_generator_and_ik_are_built_apart_and_only_the_learned_generator_needs_the_solver():
    velocity = parse_launch(minimal())
    backbone = parse_launch(minimal(generator={"type": "backbone"}))
    state = RobotState(q_rad=g1.DEFAULT_Q_RAD.copy())
    for launch, solved in ((velocity, 0), (backbone, 5)):
        generator, stage = make_generator(launch), make_ik(launch)
        generator.reset(state)
        for k in range(5):
            state.t_s = k * 0.02
            out = stage.solve(generator.update(Command(vx_mps=0.2), state), state.q_rad)
        assert stage.solved_ticks == solved
        # the in-betweening generator asks for the upper body; the velocity generator's default style does not
        assert out.upper_body_override == (solved > 0)
