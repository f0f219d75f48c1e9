"""Launch files select the WBC: tracker.type wbc, a scripted reference by name, a rate it can work at."""

import pytest

from g1_control.errors import LaunchFileError
from g1_control.launch.builder import build_loop
from g1_control.launch.schema import load_launch, parse_launch
from g1_control.trackers.wbc.tracker import WholeBodyTracker
from tests.paths import LAUNCH_DIR


def launch_dict(tracker_hz=250, **generator):
    return {"name": "wbc_test", "rates": {"tracker_hz": tracker_hz}, "tracker": {"type": "wbc"},
            "generator": {"type": "scripted", **generator},
            "input": {"type": "scripted", "timeline": [{"duration_s": 1.0}]}, "output": {"video": False}}


def test_shipped_wbc_launch_file_builds_a_wbc_loop_that_stands():
    launch = load_launch(LAUNCH_DIR / "sim_wbc_walk.yaml")
    launch.generator.reference = "stand"
    loop = build_loop(launch)
    assert isinstance(loop.tracker, WholeBodyTracker) and loop.rates.tracker_hz == 250
    loop.reset()
    loop.run(1.0)
    assert not loop.fell


def test_too_slow_a_tracker_rate_is_refused():
    with pytest.raises(LaunchFileError, match="tracker_hz: 50 Hz is too slow for tracker.type wbc"):
        parse_launch(launch_dict(tracker_hz=50))


def test_unknown_reference_is_refused():
    with pytest.raises(LaunchFileError, match="generator.reference: unknown reference 'moonwalk'"):
        parse_launch(launch_dict(reference="moonwalk"))


def test_unknown_reference_parameter_is_refused():
    with pytest.raises(LaunchFileError, match="reference_params: pace not a parameter of reference 'walk'"):
        parse_launch(launch_dict(reference="walk", reference_params={"pace": 2.0}))


def test_wbc_with_a_velocity_generator_walks_by_its_own_gait():
    from g1_control.launch.builder import make_tracker

    data = launch_dict()
    data["generator"] = {"type": "velocity"}
    assert make_tracker(parse_launch(data)).config.footsteps == "velocity"
    assert make_tracker(parse_launch(launch_dict())).config.footsteps == "plan"


def test_the_wbc_runs_at_its_own_rate_when_the_file_states_none():
    """`g1 launch sim_generator.yaml --set tracker.type=wbc`: the file states no rates, and the policies'
    50 Hz default would be refused; unstated, the WBC's 250 Hz. A stated rate is kept (and judged)."""
    data = launch_dict()
    del data["rates"]
    assert parse_launch(data).rates.tracker_hz == 250
    data["rates"] = {"input_hz": 100}
    assert parse_launch(data).rates.tracker_hz == 250 and parse_launch(data).rates.input_hz == 100
    data["tracker"] = {"type": "layer"}
    data["generator"] = {"type": "velocity"}
    assert parse_launch(data).rates.tracker_hz == 250
    data["tracker"] = {"type": "policy"}
    assert parse_launch(data).rates.tracker_hz == 50
    assert parse_launch(launch_dict(tracker_hz=100)).rates.tracker_hz == 100
    with pytest.raises(LaunchFileError, match="tracker_hz: 50 Hz is too slow"):
        parse_launch(launch_dict(tracker_hz=50))


def test_the_shipped_generator_file_runs_the_wbc_from_the_command_line():
    launch = load_launch(LAUNCH_DIR / "sim_generator.yaml", ["tracker.type=wbc"])
    assert launch.tracker.type == "wbc" and launch.rates.tracker_hz == 250
