"""The scripts in examples/ (the public API in use, docs/api.md) run to the end and check their own results."""

import os
import subprocess
import sys

import pytest

from g1_control import assets
from tests.paths import REPO

EXAMPLES = sorted((REPO / "examples").glob("*.py"))


def test_examples_are_there():
    assert {p.stem for p in EXAMPLES} >= {"run_launch_file", "commands_from_code", "swap_tracker", "retarget_clip",
                                          "ik_alone", "read_run_log"}


@pytest.mark.slow
@pytest.mark.parametrize("script", EXAMPLES, ids=[p.stem for p in EXAMPLES])
def test_example_runs(script, tmp_path):
    if script.stem == "retarget_clip" and not assets.is_fetched("holosoma-demo-mocap"):
        pytest.fail("demo mocap not fetched: run the README's test command (scripts/setup.sh --test fetches it)")
    env = dict(os.environ, PYTHONPATH=str(REPO) + os.pathsep + os.environ.get("PYTHONPATH", ""), MPLBACKEND="Agg")
    proc = subprocess.run([sys.executable, str(script)], cwd=tmp_path, env=env, capture_output=True, text=True,
                          timeout=600, check=False)
    assert proc.returncode == 0, f"{script.name} failed:\n{proc.stdout[-3000:]}\n{proc.stderr[-3000:]}"
    assert proc.stdout.strip(), f"{script.name} printed nothing"
