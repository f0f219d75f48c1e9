"""Launch files select the WBC: tracker.type wbc, a reference name, a rate it can work at."""

import pytest

from g1_control.errors import LaunchFileError
from g1_control.launch.runner import build_loop, timeline_of
from g1_control.launch.schema import load_launch, parse_launch
from g1_control.wbc.tracker import WholeBodyTracker


def launch_dict(**tracker):
    return {"name": "wbc_test", "rates": {"tracker_hz": tracker.pop("tracker_hz", 250)},
            "tracker": {"type": "wbc", **tracker},
            "input": {"type": "scripted", "timeline": [{"duration_s": 1.0}]}, "output": {"video": False}}


def test_shipped_wbc_launch_file_builds_a_wbc_loop_that_stands():
    launch = load_launch("launch/sim_wbc_walk.yaml")
    launch.tracker.wbc_reference = "stand"
    loop = build_loop(launch, timeline_of(launch))
    assert isinstance(loop.tracker, WholeBodyTracker) and loop.rates.tracker_hz == 250
    loop.reset()
    loop.run(1.0)
    assert not loop.fell


def test_too_slow_a_tracker_rate_is_refused():
    launch = parse_launch(launch_dict(tracker_hz=50))
    with pytest.raises(LaunchFileError, match="tracker_hz: 50.0 Hz is too slow for tracker.type wbc"):
        build_loop(launch, timeline_of(launch))


def test_unknown_reference_is_refused():
    launch = parse_launch(launch_dict(wbc_reference="moonwalk"))
    with pytest.raises(LaunchFileError, match="unknown reference 'moonwalk'"):
        build_loop(launch, timeline_of(launch))
