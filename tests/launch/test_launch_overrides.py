"""`--set KEY=VALUE` overrides: applied to the YAML data, then validated by the same schema."""

import pytest

from g1_control.config import apply_overrides
from g1_control.errors import LaunchFileError
from g1_control.launch.schema import load_launch
from tests.paths import LAUNCH_DIR

WALK = LAUNCH_DIR / "sim_walk.yaml"


def test_overrides_reach_every_level():
    launch = load_launch(WALK, overrides=["tracker.policy=holosoma_loco_fastsac", "safety.max_tilt_rad=0.8",
                                          "input.timeline[1].vx_mps=0.3", "output.video_size=[320, 240]",
                                          "duration_s=5"])
    assert launch.tracker.policy == "holosoma_loco_fastsac"
    assert launch.safety.max_tilt_rad == 0.8
    assert launch.input.timeline[1].vx_mps == 0.3
    assert launch.output.video_size == (320, 240)
    assert launch.duration_s == 5.0


def test_data_is_not_modified_in_place():
    data = {"tracker": {"type": "policy"}}
    out = apply_overrides(data, ["tracker.policy=x"])
    assert data == {"tracker": {"type": "policy"}} and out["tracker"]["policy"] == "x"


@pytest.mark.parametrize("override, message", [
    ("tracker.polcy=x", "tracker: unknown key 'polcy'"),
    ("safety.max_tilt_rad=fast", "safety.max_tilt_rad: expected a number"),
    ("input.timeline[1].vx_mps=5", "exceeds limits.max_vx_mps"),
    ("input.timeline[99].vx_mps=0", "no such list item"),
    ("tracker.policy", "expected KEY=VALUE"),
    ("tracker..policy=x", "not a key name"),
    ("tracker.policy=no_such_policy", "tracker.policy"),
])
def test_bad_overrides_name_the_key(override, message):
    with pytest.raises(LaunchFileError, match=message.replace("[", r"\[").replace("]", r"\]")):
        load_launch(WALK, overrides=[override])
