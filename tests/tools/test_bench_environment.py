"""The physics benches record what they ran on (tools/environment.py): the versions of the packages
that decide their numbers, read from the installed distributions, and the line they print."""

import json
import types

import mujoco
import numpy as np
import pinocchio

from g1_control.tools import bench_objects, environment


def test_the_record_names_the_versions_that_are_imported():
    env = environment.environment()
    assert env["mujoco"] == mujoco.__version__
    assert env["pin"] == pinocchio.__version__
    assert env["numpy"] == np.__version__
    assert env["python"].count(".") == 2 and env["machine"] and env["cpu"]


def test_a_package_that_is_not_installed_is_recorded_as_absent(monkeypatch):
    monkeypatch.setattr(environment, "PACKAGES", ("mujoco", "no-such-distribution-g1"))
    env = environment.environment()
    assert env["no-such-distribution-g1"] == "absent"
    line = environment.describe(env)
    assert f"mujoco {mujoco.__version__}" in line and "no-such-distribution-g1 absent" in line


def test_bench_objects_prints_and_writes_its_environment(tmp_path, capsys):
    # seed 120's trial 0 is refused by the stance search before anything moves: a short run
    out = tmp_path / "objects.json"
    args = types.SimpleNamespace(trials=1, seed=120, jobs=1, ray=None, json=str(out))
    assert bench_objects.main(args) == 0
    assert f"environment: mujoco {mujoco.__version__}, pin {pinocchio.__version__}" in capsys.readouterr().out
    assert json.loads(out.read_text())["environment"] == environment.environment()
