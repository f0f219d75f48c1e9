"""`g1 sim-robot --randomize`: bad ranges are refused naming the flag, before anything starts."""

from __future__ import annotations

import pytest

from g1_control.cli.main import main


@pytest.mark.parametrize(("flags", "message"), [
    (["--randomize-mass-scale", "1.2", "0.9"],
     "g1 sim-robot: --randomize-mass-scale: [1.2, 0.9] must be [low, high] with 0.5 <= low <= high <= 2 "
     "(a factor on each link's mass)"),
    (["--randomize-latency-s", "0.01", "0.5"],
     "g1 sim-robot: --randomize-latency-s: [0.01, 0.5] must be [low, high] with 0 <= low <= high <= 0.1 "
     "(seconds of command latency)"),
    (["--randomize-com-offset-m", "1"], "g1 sim-robot: --randomize-com-offset-m: 1 is outside [0, 0.1] m"),
    (["--physics", "mock"], "g1 sim-robot: --randomize needs --physics mujoco"),
])
def test_bad_randomisation_is_refused_naming_the_flag(capsys, flags, message):
    assert main(["sim-robot", "--randomize", "2", *flags]) == 2
    assert capsys.readouterr().err.strip() == message


def test_a_negative_seed_is_refused(capsys):
    assert main(["sim-robot", "--randomize", "-1"]) == 2
    assert capsys.readouterr().err.strip() == "g1 sim-robot: --randomize: -1 must be >= 0"
