"""The generator inside the fixed-rate loop: launch file, factory, MuJoCo physics."""

from pathlib import Path

import numpy as np
import pytest

from g1_control.errors import G1ControlError
from g1_control.generator.factory import make_generator
from g1_control.generator.retarget import GeneratorRetargeter
from g1_control.generator.runtime import InbetweeningGenerator
from g1_control.launch.runner import run
from g1_control.launch.schema import load_launch

LAUNCH = Path(__file__).resolve().parents[2] / "launch" / "sim_generator.yaml"


def test_launch_file_selects_the_backbone_and_lasts_five_minutes():
    launch = load_launch(LAUNCH)
    assert launch.generator.type == "backbone" and launch.total_duration_s == pytest.approx(300.0)
    styles = {s.style for s in launch.input.timeline}
    assert len(styles) >= 8
    gen, ret = make_generator("backbone")
    assert isinstance(gen, InbetweeningGenerator) and isinstance(ret, GeneratorRetargeter)


def test_unknown_generator_is_named():
    with pytest.raises(G1ControlError, match="unknown generator 'magic'; known: velocity, backbone"):
        make_generator("magic")


def test_generator_session_in_physics_follows_styles_and_directions_without_a_fall():
    launch = load_launch(LAUNCH)
    launch.duration_s = 40.0  # the first segments: stand, sidestep (carry), fast (arms out)
    result = run(launch, progress=False)
    assert not result.fell and not result.events
    stand, fast = result.segments[0], result.segments[2]
    assert np.abs(stand.achieved).max() < 0.05
    # Walks forward with the arms out. After 25 s of walking, float rounding alone moves this speed
    # within about 0.35-0.40 m/s (1e-12 rad/s nudges to the start state, on the same code), so the
    # bound sits below that spread.
    assert fast.achieved[0] > 0.3
    # (the carry sidestep is not checked: the loco policy walks backwards with the arms held
    # forward, with or without the generator - measured, see the issue notes)
    assert result.timings["generator"]["p50_us"] < 5000
