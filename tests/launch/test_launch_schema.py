import math
from pathlib import Path

import pytest
import yaml

from g1_control.cli.main import main
from g1_control.errors import LaunchFileError
from g1_control.launch.schema import load_launch, parse_launch

REPO = Path(__file__).resolve().parents[2]


def minimal(**extra):
    d = {"name": "t", "input": {"type": "scripted", "timeline": [{"duration_s": 1.0, "vx_mps": 0.2}]}}
    d.update(extra)
    return d


def test_shipped_launch_files_validate():
    """Every shipped launch file loads, and holds every value its YAML gives."""
    from tests.launch.launch_schema_data import assert_holds

    paths = sorted((REPO / "launch").glob("*.yaml"))
    assert len(paths) >= 10
    for path in paths:
        assert_holds(load_launch(path), yaml.safe_load(path.read_text()), path.name)


def test_unknown_key_is_named_with_its_path():
    with pytest.raises(LaunchFileError, match="tracker: unknown key 'polcy'; allowed: type, policy"):
        parse_launch(minimal(tracker={"polcy": "x"}))


def test_wrong_type_is_named():
    with pytest.raises(LaunchFileError, match="rates.tracker_hz: expected a number, got 'fast'"):
        parse_launch(minimal(rates={"tracker_hz": "fast"}))
    with pytest.raises(LaunchFileError, match="backend.mode: expected one of 'lockstep', 'wallclock', got 'turbo'"):
        parse_launch(minimal(backend={"mode": "turbo"}))


def test_missing_required_field():
    with pytest.raises(LaunchFileError, match="name: required field is missing"):
        parse_launch({"input": minimal()["input"]})
    with pytest.raises(LaunchFileError, match=r"input.timeline\[0\].duration_s: required field is missing"):
        parse_launch(minimal(input={"timeline": [{"vx_mps": 0.1}]}))


def test_nan_command_is_refused():
    d = minimal(input={"timeline": [{"duration_s": 1.0, "vx_mps": math.nan}]})
    with pytest.raises(LaunchFileError, match=r"input.timeline\[0\].vx_mps: expected a finite number, got nan"):
        parse_launch(d)


def test_command_beyond_limits_and_bad_rates():
    with pytest.raises(LaunchFileError, match=r"input.timeline\[0\].vx_mps: 2.0 exceeds limits.max_vx_mps"):
        parse_launch(minimal(input={"timeline": [{"duration_s": 1.0, "vx_mps": 2.0}]}))
    with pytest.raises(LaunchFileError, match="rates.tracker_hz: 30.0 Hz must divide the low-level rate"):
        parse_launch(minimal(rates={"tracker_hz": 30}))
    with pytest.raises(LaunchFileError, match="physics must run at 200 Hz or faster"):
        parse_launch(minimal(backend={"physics_dt_s": 0.01}))


def test_cli_check_reports_error_and_runs_nothing(tmp_path, capsys):
    bad = tmp_path / "bad.yaml"
    bad.write_text(yaml.safe_dump(minimal(tracker={"policy": "no_such_policy"}, output={"dir": str(tmp_path / "runs")})))
    assert main(["launch", str(bad)]) == 1
    err = capsys.readouterr().err
    assert "tracker.policy: unknown policy 'no_such_policy'" in err
    assert not (tmp_path / "runs").exists()
    broken = tmp_path / "broken.yaml"
    broken.write_text("name: [unclosed")
    assert main(["launch", str(broken), "--check"]) == 1
    assert "not valid YAML" in capsys.readouterr().err


def test_cli_check_ok(capsys):
    assert main(["launch", str(REPO / "launch" / "sim_walk.yaml"), "--check"]) == 0
    assert "OK" in capsys.readouterr().out
