"""The wheel: built from this checkout, installed into a fresh virtual environment, it runs the
quick start's --check from an unrelated directory, finds its launch files and docs, and carries
only runtime files plus the license texts.

Fast on purpose: the venv also sees this environment's packages (a .pth file adds its
site-packages after the venv's own; --system-site-packages would not do inside another venv)
and the wheel goes in with --no-deps, so nothing is downloaded; the test checks that g1_control
is imported from the wheel, not from this checkout.
"""

import os
import shutil
import subprocess
import sys
import sysconfig
import zipfile
from pathlib import Path

import pytest

from tests.paths import REPO

SKIP = shutil.ignore_patterns(".git", ".venv", "runs", "build", "dist", "*.egg-info", "__pycache__", ".pytest_cache",
                              ".hypothesis", ".gl", ".whl", "*.mp4")


def _setuptools_new_enough() -> bool:
    # Read the version without importing setuptools: its distutils shim refuses to load after
    # another package imported the stdlib's distutils (seen in a Debian venv).
    from importlib.metadata import PackageNotFoundError, version

    try:
        return int(version("setuptools").split(".")[0]) >= 77
    except PackageNotFoundError:
        return False


@pytest.fixture(scope="module")
def wheel(tmp_path_factory):
    src = tmp_path_factory.mktemp("src") / "g1-control"
    shutil.copytree(REPO, src, ignore=SKIP)
    dist = tmp_path_factory.mktemp("dist")
    # Without build isolation when this environment's setuptools can build it (no download).
    isolation = ["--no-build-isolation"] if _setuptools_new_enough() else []
    cmd = [sys.executable, "-m", "pip", "wheel", "-q", "--no-deps", *isolation, "-w", str(dist), str(src)]
    subprocess.run(cmd, check=True, capture_output=True, timeout=600)
    (found,) = dist.glob("g1_control-*.whl")
    return found


def test_wheel_carries_runtime_files_launch_files_docs_and_licenses(wheel):
    names = set(zipfile.ZipFile(wheel).namelist())
    for launch in (REPO / "launch").glob("*.yaml"):
        assert f"g1_control/_shipped/launch/{launch.name}" in names
    for doc in ("README.md", "LICENSE", "THIRD_PARTY_LICENSES.md", "architecture.md", "api.md", "robot_facts.md"):
        assert f"g1_control/_shipped/docs/{doc}" in names
    assert "g1_control/deploy/README.md" in names and "g1_control/teleop/README.md" in names
    # what the generators read at run time: the backbone, its skeletons and mixtures, learned motion matching
    for shipped in ("backbone.onnx", "model.json", "feedback.npz", "style_stats.json", "lmm/lmm.onnx", "lmm/model.json"):
        assert f"g1_control/policies/generator/{shipped}" in names
    assert any(n.endswith(".dist-info/licenses/LICENSE") for n in names)
    leftovers = [n for n in names if n.endswith((".pt", "loss_history.json", "loss.png"))]
    assert not leftovers, f"training leftovers in the wheel: {leftovers}"
    assert not [n for n in names if n.startswith(("tests/", "examples/", "scripts/"))]


@pytest.mark.slow
def test_installed_wheel_runs_the_quick_start_check_anywhere(wheel, tmp_path):
    venv = tmp_path / "venv"
    subprocess.run([sys.executable, "-m", "venv", "--without-pip", str(venv)], check=True, timeout=120)
    py, g1 = venv / "bin" / "python", venv / "bin" / "g1"
    venv_site = subprocess.run([str(py), "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
                               check=True, capture_output=True, text=True).stdout.strip()
    ours = {sysconfig.get_paths()["purelib"], sysconfig.get_paths()["platlib"]}
    (Path(venv_site) / "_this_environment.pth").write_text(
        "".join(f"import site; site.addsitedir({d!r})\n" for d in sorted(ours)))
    subprocess.run([str(py), "-m", "pip", "install", "-q", "--no-deps", "--no-index", "--ignore-installed",
                    "--disable-pip-version-check", str(wheel)], check=True, capture_output=True, timeout=300)
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}

    def run(*args):
        proc = subprocess.run(list(args), cwd=elsewhere, env=env, capture_output=True, text=True, timeout=300,
                              check=False)
        assert proc.returncode == 0, f"{args} failed:\n{proc.stdout}\n{proc.stderr}"
        return proc.stdout

    where = run(str(py), "-c", "import g1_control, sys; print(g1_control.__file__)")
    assert where.startswith(str(venv)), f"g1_control imported from {where}, not from the wheel"
    assert str(venv) in run(str(g1), "--version")
    assert "OK (sim_walk" in run(str(g1), "launch", "sim_walk", "--check")
    assert "OK (sim_walk" in run(str(g1), "launch", "launch/sim_walk.yaml", "--check")  # the README's paths
    assert "OK (sim_tour" in run(str(g1), "launch", "launch/sim_tour.yaml", "--check")
    assert "sim_walk" in run(str(g1), "launch", "--list")
    run(str(g1), "init", "mine")
    assert (elsewhere / "mine" / "sim_walk.yaml").is_file()
    assert "OK (sim_walk" in run(str(g1), "launch", "mine/sim_walk.yaml", "--check")
    assert "preflight" in run(str(g1), "docs", "deploy").lower()
    assert "BSD 3-Clause" in run(str(g1), "docs", "license")
